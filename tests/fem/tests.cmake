diffpd_add_test(muscle_forces_test ${CMAKE_CURRENT_LIST_DIR}/muscle_forces_test.cc LIBS diffpd_problems)
diffpd_add_test(penalty_contact_energy_test ${CMAKE_CURRENT_LIST_DIR}/penalty_contact_energy_test.cc)
diffpd_add_test(mass_model_test ${CMAKE_CURRENT_LIST_DIR}/mass_model_test.cc)
diffpd_add_test(elastic_forces_test ${CMAKE_CURRENT_LIST_DIR}/elastic_forces_test.cc)
