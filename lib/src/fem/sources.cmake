# Sources of the fem area (paths relative to lib/).
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/fem_model.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/elastic_forces.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/pd_hex_kernel.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/packed_element_matrices.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/muscle_forces.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/penalty_contact_energy.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/auxiliary_energies.cc)
list(APPEND DIFFPD_LIB_SOURCES ${CMAKE_CURRENT_LIST_DIR}/mass_model.cc)
