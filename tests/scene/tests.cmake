diffpd_add_test(material_regions_test ${CMAKE_CURRENT_LIST_DIR}/material_regions_test.cc)
diffpd_add_test(scene_test ${CMAKE_CURRENT_LIST_DIR}/scene_test.cc)
diffpd_add_test(mass_lumping_test ${CMAKE_CURRENT_LIST_DIR}/mass_lumping_test.cc)
