# Sources of the control area (paths relative to lib/): closed-loop
# controllers, their network and muscle strips.
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/mlp.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/muscle_strip.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/strip_drive.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/strip_network_controller.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/strip_open_loop_controller.cc)
