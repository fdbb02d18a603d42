# The problems library, by kind (mirrors problems/).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
diffpd_add_test(contact_problems_test ${_dir}/scenes/contact_problems_test.cc LIBS diffpd_problems)
diffpd_add_test(bench_test ${_dir}/tools/bench_test.cc LIBS diffpd_problems)
diffpd_add_test(tradeoff_test ${_dir}/tools/tradeoff_test.cc LIBS diffpd_problems)
diffpd_add_test(tradeoff_front_test ${_dir}/tools/tradeoff_front_test.cc LIBS diffpd_problems)
diffpd_add_test(tradeoff_problems_test ${_dir}/tools/tradeoff_problems_test.cc LIBS diffpd_problems)
diffpd_add_test(stress_test ${_dir}/tools/stress_test.cc LIBS diffpd_problems)
diffpd_add_test(derivative_verdict_test ${_dir}/tools/derivative_verdict_test.cc LIBS diffpd_problems)
diffpd_add_test(gradcheck_test ${_dir}/tools/gradcheck_test.cc LIBS diffpd_problems)
# Calibration problems (with the Ceres adapter) and control problems (with the Ipopt adapter).
if(TARGET diffpd_ceres)
  diffpd_add_test(calibrate_cantilever_test ${_dir}/calibration/calibrate_cantilever_test.cc LIBS diffpd_problems)
  diffpd_add_test(calibrate_plant_test ${_dir}/calibration/calibrate_plant_test.cc LIBS diffpd_problems)
  diffpd_add_test(plant_recordings_test ${_dir}/calibration/plant_recordings_test.cc LIBS diffpd_problems)
  diffpd_add_test(calibrate_bouncing_ball_test ${_dir}/calibration/calibrate_bouncing_ball_test.cc LIBS diffpd_problems)
  diffpd_add_test(calibrate_starfish_test ${_dir}/calibration/calibrate_starfish_test.cc LIBS diffpd_problems)
  diffpd_add_test(starfish_covariance_check_test ${_dir}/calibration/starfish_covariance_check_test.cc
                  LIBS diffpd_problems)
  diffpd_add_test(starfish_recordings_fit_test ${_dir}/calibration/starfish_recordings_fit_test.cc
                  LIBS diffpd_problems)
  diffpd_add_test(starfish_fit_starts_test ${_dir}/calibration/starfish_fit_starts_test.cc LIBS diffpd_problems)
endif()
if(TARGET diffpd_ipopt)
  diffpd_add_test(bunny_test ${_dir}/control/bunny_test.cc LIBS diffpd_problems)
  diffpd_add_test(locomotion_torus_test ${_dir}/control/locomotion_torus_test.cc LIBS diffpd_problems)
  diffpd_add_test(locomotion_quadruped_test ${_dir}/control/locomotion_quadruped_test.cc LIBS diffpd_problems)
  diffpd_add_test(locomotion_cow_test ${_dir}/control/locomotion_cow_test.cc LIBS diffpd_problems)
  diffpd_add_test(routing_tendon_opt_test ${_dir}/control/routing_tendon_opt_test.cc LIBS diffpd_problems)
  diffpd_add_test(trajectory_optimization_test ${_dir}/control/trajectory_optimization_test.cc LIBS diffpd_problems)
  diffpd_add_test(optimiser_tradeoff_test ${_dir}/tools/optimiser_tradeoff_test.cc LIBS diffpd_problems)
endif()
diffpd_add_test(command_line_test ${_dir}/cli/command_line_test.cc LIBS diffpd_problems)
# The program's OpenMP waits (tools/openmp_waits.h), through the program itself.
add_test(NAME diffpd_sets_short_openmp_waits
         COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:diffpd_cli> -DSPIN=1000 -P ${_dir}/cli/openmp_waits.cmake)
# Every problem's trade-off front is monotone: `diffpd tradeoff --all --check`
# runs pd-lbfgs's tolerance sweep (1e-2, 1e-4, 1e-6) on every problem's small
# instance against its converged reference and exits with status 6 when a
# tighter tolerance gives a state, loss or gradient error above 3x (--noise) a
# looser one's plus 1e-9. Four shards so that ctest -j spreads them.
foreach(shard 1 2 3 4)
  add_test(NAME tradeoff_fronts_monotone_shard_${shard}_of_4
           COMMAND diffpd_cli tradeoff --all --shard ${shard}/4 --check --noise 3 --threads 1)
  set_tests_properties(tradeoff_fronts_monotone_shard_${shard}_of_4 PROPERTIES ENVIRONMENT "OMP_NUM_THREADS=1")
endforeach()
# Closed-loop swimming (Adam needs neither adapter).
diffpd_add_test(adam_test ${_dir}/control/adam_test.cc LIBS diffpd_problems)
diffpd_add_test(swimmer_scenes_test ${_dir}/control/swimmer_scenes_test.cc LIBS diffpd_problems)
diffpd_add_test(starfish_control_test ${_dir}/control/starfish_control_test.cc LIBS diffpd_problems)
diffpd_add_test(swimmer_starts_test ${_dir}/control/swimmer_starts_test.cc LIBS diffpd_problems)
diffpd_add_test(shark_control_test ${_dir}/control/shark_control_test.cc LIBS diffpd_problems)
diffpd_add_test(numpy_random_test ${_dir}/paper/numpy_random_test.cc LIBS diffpd_problems)
diffpd_add_test(paper_rows_test ${_dir}/paper/paper_rows_test.cc LIBS diffpd_problems)
diffpd_add_test(row_gradient_test ${_dir}/paper/row_gradient_test.cc LIBS diffpd_problems)
diffpd_add_test(activation_variables_test ${_dir}/paper/activation_variables_test.cc LIBS diffpd_problems)
diffpd_add_test(table_test ${_dir}/tools/table_test.cc LIBS diffpd_problems)
# The rows optimised by L-BFGS-B and, with the Ipopt adapter, by Ipopt.
diffpd_add_test(row_optimisation_test ${_dir}/paper/row_optimisation_test.cc LIBS diffpd_problems)
if(TARGET diffpd_ipopt)
  target_compile_definitions(row_optimisation_test PRIVATE DIFFPD_TEST_IPOPT=1)
endif()
# Problems over MPI ranks (diffpd-mpi and what it runs).
if(TARGET diffpd_mpi AND TARGET diffpd_ceres)
  include(${_dir}/mpi/tests.cmake)
endif()
