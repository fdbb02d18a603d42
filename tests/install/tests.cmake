# The installed package works for another project: find_package(DiffPD
# COMPONENTS ...) with the adapters this build has, linking DiffPD::diffpd,
# DiffPD::solvers_core and DiffPD::ceres / DiffPD::ipopt.
set(_components "")
foreach(_component ceres ipopt)
  if(TARGET diffpd_${_component})
    list(APPEND _components ${_component})
  endif()
endforeach()
string(REPLACE ";" "," _components "${_components}")
add_test(NAME install_consumer_test
  COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${CMAKE_BINARY_DIR} -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
          -DWORK_DIR=${CMAKE_BINARY_DIR}/install-consumer-test -DCOMPONENTS=${_components}
          -P ${CMAKE_CURRENT_LIST_DIR}/consumer_test.cmake)
