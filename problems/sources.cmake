# Sources of the problems library (paths relative to problems/), by kind:
# the problem interface and registry, scenes, tools (bench, tradeoff, stress,
# gradcheck) and the command-line program's subcommands; calibration (with
# the Ceres adapter) and control (with the Ipopt adapter) in lists of their
# own, compiled when the adapter is built.
set(DIFFPD_PROBLEMS_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/problem_registry.cc
  ${CMAKE_CURRENT_LIST_DIR}/shared_data.cc
  # scenes
  ${CMAKE_CURRENT_LIST_DIR}/scenes/cantilever.cc
  ${CMAKE_CURRENT_LIST_DIR}/scenes/cantilever_plane.cc
  ${CMAKE_CURRENT_LIST_DIR}/scenes/rolling_sphere.cc
  ${CMAKE_CURRENT_LIST_DIR}/scenes/bouncing_ball.cc
  ${CMAKE_CURRENT_LIST_DIR}/scenes/routing_tendon.cc
  # control: closed-loop swimming, controllers trained through the simulation
  ${CMAKE_CURRENT_LIST_DIR}/control/adam.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/swim_loss.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/evaluation_budget.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/swimmer_adam.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/swimmer_control.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/reference_curve.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/starfish_control.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/shark_control.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/swimmer_starts.cc
  # paper: the DiffPD paper's table rows as data
  ${CMAKE_CURRENT_LIST_DIR}/paper/numpy_random.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/paper_meshes.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/log_material_variables.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/rigid_placement_variables.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/activation_variables.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/trajectory_losses.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/paper_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/paper_rows.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/cantilever_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/rolling_sphere_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/plant_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/bouncing_ball_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/bunny_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/routing_tendon_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/torus_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/quadruped_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/cow_row.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/swimmer_rows.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/row_evaluation.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/row_rollout_function.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/row_optimisation.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/row_lbfgsb_optimisation.cc
  # tools
  ${CMAKE_CURRENT_LIST_DIR}/tools/openmp_waits.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/derivative_verdict.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/gradcheck.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/bench.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/problem_objective.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/reference_cache.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/tradeoff.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/tradeoff_front.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/optimiser_tradeoff.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/stress.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/table.cc
  ${CMAKE_CURRENT_LIST_DIR}/tools/table_report.cc
  # the diffpd program's subcommands (main.cc is the executable's)
  ${CMAKE_CURRENT_LIST_DIR}/cli/command_line.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/option_checks.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/run_options.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/list_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/run_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/gradcheck_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/bench_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/tradeoff_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/stress_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/synth_command.cc
  ${CMAKE_CURRENT_LIST_DIR}/cli/table_command.cc)
# calibration: system identification with Ceres
set(DIFFPD_PROBLEMS_CALIBRATION_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/calibration/iteration_table.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/material_fit_settings.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/calibrate_problem.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/calibrate_cantilever.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/calibrate_plant.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/calibrate_bouncing_ball.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_recording.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_scene.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_actuation.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_metrics.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_trace.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_plot.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_fit.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_fit_starts.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_covariance_check.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/calibrate_starfish.cc
  # calibration over several recordings (a rollout set)
  ${CMAKE_CURRENT_LIST_DIR}/calibration/plant_recordings.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/rollout_set_fit.cc
  ${CMAKE_CURRENT_LIST_DIR}/calibration/starfish_recordings_fit.cc
  # the swimmers' L-BFGS training
  ${CMAKE_CURRENT_LIST_DIR}/control/swimmer_lbfgs.cc)
# control: trajectory and control optimisation with Ipopt
set(DIFFPD_PROBLEMS_CONTROL_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/control/trajectory_optimization.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/bunny.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/routing_tendon_opt.cc
  ${CMAKE_CURRENT_LIST_DIR}/control/locomotion.cc
  ${CMAKE_CURRENT_LIST_DIR}/paper/row_ipopt_optimisation.cc
  # the swimmers' Ipopt training
  ${CMAKE_CURRENT_LIST_DIR}/control/swimmer_ipopt.cc)
get_filename_component(DIFFPD_DEFAULT_SHARED_DATA_DIR "${CMAKE_CURRENT_LIST_DIR}/../../shared/data" ABSOLUTE)
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/shared_data.cc PROPERTIES
  COMPILE_DEFINITIONS "DIFFPD_SHARED_DATA_DIR=\"${DIFFPD_DEFAULT_SHARED_DATA_DIR}\"")
get_filename_component(DIFFPD_SOURCE_ROOT "${CMAKE_CURRENT_LIST_DIR}/.." ABSOLUTE)
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/tools/table.cc PROPERTIES
  COMPILE_DEFINITIONS "DIFFPD_SOURCE_DIR=\"${DIFFPD_SOURCE_ROOT}\"")
set_source_files_properties(${CMAKE_CURRENT_LIST_DIR}/calibration/calibrate_problem.cc PROPERTIES
  COMPILE_DEFINITIONS "DIFFPD_PROJECT_DATA_DIR=\"${CMAKE_CURRENT_LIST_DIR}/../data\"")
