# The installed package works for another project: find_package(DiffPD) and
# link DiffPD::diffpd.
add_test(NAME install_consumer_test
  COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${CMAKE_BINARY_DIR} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
          -DWORK_DIR=${CMAKE_BINARY_DIR}/install-consumer-test -P ${CMAKE_CURRENT_LIST_DIR}/consumer_test.cmake)
