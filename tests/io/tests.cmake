# Tests of the io area.
diffpd_add_test(vtk_writer_test ${CMAKE_CURRENT_LIST_DIR}/vtk_writer_test.cc)
