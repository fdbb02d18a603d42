diffpd_add_test(mlp_test ${CMAKE_CURRENT_LIST_DIR}/mlp_test.cc)
diffpd_add_test(muscle_strip_test ${CMAKE_CURRENT_LIST_DIR}/muscle_strip_test.cc)
diffpd_add_test(strip_network_controller_test ${CMAKE_CURRENT_LIST_DIR}/strip_network_controller_test.cc)
