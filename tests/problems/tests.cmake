diffpd_add_test(bench_test ${CMAKE_CURRENT_LIST_DIR}/bench_test.cc LIBS diffpd_problems)
diffpd_add_test(tradeoff_test ${CMAKE_CURRENT_LIST_DIR}/tradeoff_test.cc LIBS diffpd_problems)
diffpd_add_test(stress_test ${CMAKE_CURRENT_LIST_DIR}/stress_test.cc LIBS diffpd_problems)
