diffpd_add_test(ipopt_rollout_nlp_test ${CMAKE_CURRENT_LIST_DIR}/ipopt_rollout_nlp_test.cc LIBS diffpd_solvers)
diffpd_add_test(captured_motion_test ${CMAKE_CURRENT_LIST_DIR}/captured_motion_test.cc)
diffpd_add_test(ipopt_solve_test ${CMAKE_CURRENT_LIST_DIR}/ipopt_solve_test.cc LIBS diffpd_solvers)
