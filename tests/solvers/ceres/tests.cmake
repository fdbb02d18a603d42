# The Ceres adapter (solvers/ceres/).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
diffpd_add_test(gradient_checker_test ${_dir}/gradient_checker_test.cc LIBS diffpd_ceres)
diffpd_add_test(rollout_cost_function_test ${_dir}/rollout_cost_function_test.cc LIBS diffpd_ceres)
diffpd_add_test(rollout_loss_function_test ${_dir}/rollout_loss_function_test.cc LIBS diffpd_ceres)
diffpd_add_test(calibration_recovery_test ${_dir}/calibration_recovery_test.cc LIBS diffpd_ceres)
diffpd_add_test(coordinate_manifold_test ${_dir}/coordinate_manifold_test.cc LIBS diffpd_ceres GTest::gmock)
# The README's Ceres example program, run on synthetic data by readme_example_test.
add_executable(readme_example ${_dir}/readme_example.cc)
target_link_libraries(readme_example PRIVATE diffpd_ceres diffpd_compile_options)
diffpd_add_test(readme_example_test ${_dir}/readme_example_test.cc)
target_compile_definitions(readme_example_test PRIVATE DIFFPD_README_EXAMPLE="$<TARGET_FILE:readme_example>")
add_dependencies(readme_example_test readme_example)
