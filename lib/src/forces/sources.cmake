# Sources of the forces area (paths relative to lib/).
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/optional_terms_validation.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/hydrodynamic_force.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/state_forces.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/boundary_surface.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/activation_scope.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/quad_hydrodynamic_force.cc)
