# Sources of the problems library (paths relative to problems/).
set(DIFFPD_PROBLEMS_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/problem_registry.cc
  ${CMAKE_CURRENT_LIST_DIR}/cantilever.cc
  ${CMAKE_CURRENT_LIST_DIR}/gradcheck.cc
  ${CMAKE_CURRENT_LIST_DIR}/list_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/run_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/gradcheck_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/bench.cc
  ${CMAKE_CURRENT_LIST_DIR}/bench_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/tradeoff.cc
  ${CMAKE_CURRENT_LIST_DIR}/tradeoff_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/stress.cc
  ${CMAKE_CURRENT_LIST_DIR}/stress_command.cc)
