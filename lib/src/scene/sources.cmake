# Sources of the scene area (paths relative to lib/).
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/scene.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/material_regions.cc)
