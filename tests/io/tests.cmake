# Tests of the io area.
diffpd_add_test(vtk_writer_test ${CMAKE_CURRENT_LIST_DIR}/vtk_writer_test.cc)
diffpd_add_test(csv_fields_test ${CMAKE_CURRENT_LIST_DIR}/csv_fields_test.cc)
diffpd_add_test(captured_motion_test ${CMAKE_CURRENT_LIST_DIR}/captured_motion_test.cc)
diffpd_add_test(input_file_test ${CMAKE_CURRENT_LIST_DIR}/input_file_test.cc)
