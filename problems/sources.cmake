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
# Trajectory and control optimisation with Ipopt (issue 6).
list(APPEND DIFFPD_PROBLEMS_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/shared_data.cc
  ${CMAKE_CURRENT_LIST_DIR}/trajectory_optimization.cc
  ${CMAKE_CURRENT_LIST_DIR}/bunny.cc
  ${CMAKE_CURRENT_LIST_DIR}/routing_tendon_opt.cc
  ${CMAKE_CURRENT_LIST_DIR}/locomotion.cc)
get_filename_component(DIFFPD_DEFAULT_SHARED_DATA_DIR "${CMAKE_CURRENT_LIST_DIR}/../../shared/data" ABSOLUTE)
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/shared_data.cc PROPERTIES
  COMPILE_DEFINITIONS "DIFFPD_SHARED_DATA_DIR=\"${DIFFPD_DEFAULT_SHARED_DATA_DIR}\"")
# Contact, muscles and state forces: problems and the contact benchmark scene.
list(APPEND DIFFPD_PROBLEMS_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/rolling_sphere.cc
  ${CMAKE_CURRENT_LIST_DIR}/bouncing_ball.cc
  ${CMAKE_CURRENT_LIST_DIR}/routing_tendon.cc
  ${CMAKE_CURRENT_LIST_DIR}/cantilever_plane.cc)
# System identification with Ceres (issue 5): calibration problems and the
# generator of their captured motion in data/.
list(APPEND DIFFPD_PROBLEMS_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/calibrate_problem.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibrate_plant.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibrate_bouncing_ball.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibrate_starfish.cc
  ${CMAKE_CURRENT_LIST_DIR}/synth_command.cc)
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/calibrate_problem.cc PROPERTIES
  COMPILE_DEFINITIONS "DIFFPD_PROJECT_DATA_DIR=\"${CMAKE_CURRENT_LIST_DIR}/../data\"")
