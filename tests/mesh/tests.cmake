# Tests of the mesh area.
diffpd_add_test(mesh_test ${CMAKE_CURRENT_LIST_DIR}/mesh_test.cc)
diffpd_add_test(box_mesh_test ${CMAKE_CURRENT_LIST_DIR}/box_mesh_test.cc)
diffpd_add_test(voxelizer_test ${CMAKE_CURRENT_LIST_DIR}/voxelizer_test.cc)
diffpd_add_test(surface_mesh_test ${CMAKE_CURRENT_LIST_DIR}/surface_mesh_test.cc)
diffpd_add_test(obj_reader_test ${CMAKE_CURRENT_LIST_DIR}/obj_reader_test.cc)
diffpd_add_test(tetgen_io_test ${CMAKE_CURRENT_LIST_DIR}/tetgen_io_test.cc)
diffpd_add_test(gmsh_io_test ${CMAKE_CURRENT_LIST_DIR}/gmsh_io_test.cc)
