# The distributed rollout set (solvers/mpi/): run on 2 ranks by mpiexec
# (--oversubscribe: CI machines may have fewer cores; the variables let
# OpenMPI run as root, as CI does, and start local ranks without ssh).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
add_executable(distributed_rollout_set_test ${_dir}/distributed_rollout_set_test.cc)
target_link_libraries(distributed_rollout_set_test PRIVATE diffpd_mpi diffpd_test_util GTest::gtest
                      diffpd_compile_options)
target_include_directories(distributed_rollout_set_test PRIVATE ${PROJECT_SOURCE_DIR}/lib/src ${PROJECT_SOURCE_DIR}/tests)
add_test(NAME distributed_rollout_set_test
         COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe ${MPIEXEC_PREFLAGS}
                 $<TARGET_FILE:distributed_rollout_set_test> ${MPIEXEC_POSTFLAGS})
# Extra NAME=VALUE entries (;-separated) for the environment of every test run
# by mpiexec (here and in tests/problems/mpi/); scripts/sanitize.sh sets the
# leak checker's options with it.
set(DIFFPD_MPI_TEST_ENVIRONMENT "" CACHE STRING "Extra NAME=VALUE entries (;-separated) for distributed_rollout_set_test")
set_tests_properties(distributed_rollout_set_test PROPERTIES
  ENVIRONMENT "OMP_NUM_THREADS=1;OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_plm=isolated;${DIFFPD_MPI_TEST_ENVIRONMENT}")
