# Sources of the fem area (paths relative to lib/).
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/fem_model.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/elastic_forces.cc)
