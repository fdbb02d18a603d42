# GoogleTest suites of the material area.
diffpd_add_test(svd3_test ${CMAKE_CURRENT_LIST_DIR}/svd3_test.cc)
diffpd_add_test(projections_test ${CMAKE_CURRENT_LIST_DIR}/projections_test.cc)
diffpd_add_test(material_test ${CMAKE_CURRENT_LIST_DIR}/material_test.cc)
diffpd_add_test(density_kernels_test ${CMAKE_CURRENT_LIST_DIR}/density_kernels_test.cc)
