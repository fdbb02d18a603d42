diffpd_add_test(hydrodynamic_force_test ${CMAKE_CURRENT_LIST_DIR}/hydrodynamic_force_test.cc)
diffpd_add_test(state_forces_test ${CMAKE_CURRENT_LIST_DIR}/state_forces_test.cc LIBS diffpd_problems)
