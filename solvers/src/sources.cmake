# Sources of the optimiser adapters (paths relative to solvers/).
set(DIFFPD_SOLVERS_SOURCES ${CMAKE_CURRENT_LIST_DIR}/optimizer_versions.cc)
