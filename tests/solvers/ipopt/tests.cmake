# The Ipopt adapter (solvers/ipopt/).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
diffpd_add_test(rollout_nlp_test ${_dir}/rollout_nlp_test.cc LIBS diffpd_ipopt)
diffpd_add_test(rollout_set_nlp_test ${_dir}/rollout_set_nlp_test.cc LIBS diffpd_ipopt)
diffpd_add_test(ipopt_solve_test ${_dir}/ipopt_solve_test.cc LIBS diffpd_ipopt)
diffpd_add_test(linear_constraint_test ${_dir}/linear_constraint_test.cc LIBS diffpd_ipopt)
diffpd_add_test(derivative_test_test ${_dir}/derivative_test_test.cc LIBS diffpd_ipopt)
# The README's Ipopt example program, run by readme_ipopt_example_test.
add_executable(readme_ipopt_example ${_dir}/readme_ipopt_example.cc)
target_link_libraries(readme_ipopt_example PRIVATE diffpd_ipopt diffpd_compile_options)
diffpd_add_test(readme_ipopt_example_test ${_dir}/readme_ipopt_example_test.cc)
target_compile_definitions(readme_ipopt_example_test PRIVATE
  DIFFPD_README_IPOPT_EXAMPLE="$<TARGET_FILE:readme_ipopt_example>")
add_dependencies(readme_ipopt_example_test readme_ipopt_example)
