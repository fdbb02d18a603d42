# The Ipopt adapter (solvers/ipopt/).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
diffpd_add_test(rollout_nlp_test ${_dir}/rollout_nlp_test.cc LIBS diffpd_ipopt)
diffpd_add_test(ipopt_solve_test ${_dir}/ipopt_solve_test.cc LIBS diffpd_ipopt)
diffpd_add_test(linear_constraint_test ${_dir}/linear_constraint_test.cc LIBS diffpd_ipopt)
diffpd_add_test(derivative_test_test ${_dir}/derivative_test_test.cc LIBS diffpd_ipopt)
