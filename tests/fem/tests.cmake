diffpd_add_test(muscle_forces_test ${CMAKE_CURRENT_LIST_DIR}/muscle_forces_test.cc LIBS diffpd_problems)
