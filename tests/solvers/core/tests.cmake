# The rollout core (solvers/core/).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
diffpd_add_test(parameter_block_derivatives_test ${_dir}/parameter_block_derivatives_test.cc LIBS diffpd_solvers_core)
diffpd_add_test(rollout_function_test ${_dir}/rollout_function_test.cc LIBS diffpd_solvers_core)
diffpd_add_test(parameter_blocks_test ${_dir}/parameter_blocks_test.cc LIBS diffpd_solvers_core)
diffpd_add_test(control_signal_test ${_dir}/control_signal_test.cc LIBS diffpd_solvers_core)
diffpd_add_test(trajectory_function_test ${_dir}/trajectory_function_test.cc LIBS diffpd_solvers_core)
diffpd_add_test(controller_block_test ${_dir}/controller_block_test.cc LIBS diffpd_solvers_core)
diffpd_add_test(rollout_set_test ${_dir}/rollout_set_test.cc LIBS diffpd_solvers_core)
