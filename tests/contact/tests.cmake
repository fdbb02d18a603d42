diffpd_add_test(contact_surface_test ${CMAKE_CURRENT_LIST_DIR}/contact_surface_test.cc)
diffpd_add_test(active_set_erasure_test ${CMAKE_CURRENT_LIST_DIR}/active_set_erasure_test.cc)
diffpd_add_test(active_set_step_test ${CMAKE_CURRENT_LIST_DIR}/active_set_step_test.cc LIBS diffpd_problems)
diffpd_add_test(contact_problems_test ${CMAKE_CURRENT_LIST_DIR}/contact_problems_test.cc LIBS diffpd_problems)
# Not a test: prints the Woodbury / refactorisation and inactive-plane timings.
add_executable(contact_benchmark ${CMAKE_CURRENT_LIST_DIR}/contact_benchmark.cc)
target_link_libraries(contact_benchmark PRIVATE diffpd diffpd_problems diffpd_compile_options)
target_include_directories(contact_benchmark PRIVATE ${PROJECT_SOURCE_DIR}/lib/src)
