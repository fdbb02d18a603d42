# The problems over MPI ranks (with DiffPD::mpi and the Ceres adapter), run
# on 2 ranks by mpiexec as tests/solvers/mpi/tests.cmake runs its test
# (--oversubscribe: CI machines may have fewer cores; the variables let
# OpenMPI run as root and start local ranks without ssh).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
# DIFFPD_MPI_TEST_ENVIRONMENT: as in tests/solvers/mpi/tests.cmake.
set(_mpi_env
    "OMP_NUM_THREADS=1;OMPI_ALLOW_RUN_AS_ROOT=1;OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1;OMPI_MCA_plm=isolated;${DIFFPD_MPI_TEST_ENVIRONMENT}")
add_executable(distributed_swimmer_training_test ${_dir}/distributed_swimmer_training_test.cc)
target_link_libraries(distributed_swimmer_training_test PRIVATE diffpd_problems diffpd_mpi diffpd_test_util GTest::gtest
                      diffpd_compile_options)
target_include_directories(distributed_swimmer_training_test PRIVATE ${PROJECT_SOURCE_DIR}/lib/src
                           ${PROJECT_SOURCE_DIR}/tests)
add_test(NAME distributed_swimmer_training_test
         COMMAND ${MPIEXEC_EXECUTABLE} ${MPIEXEC_NUMPROC_FLAG} 2 --oversubscribe ${MPIEXEC_PREFLAGS}
                 $<TARGET_FILE:distributed_swimmer_training_test> ${MPIEXEC_POSTFLAGS})
set_tests_properties(distributed_swimmer_training_test PROPERTIES ENVIRONMENT "${_mpi_env}")

# diffpd-mpi itself: each command's JSON report on 2 ranks equals the 1-rank
# report (everything but its "run" member: ranks, threads, seconds).
function(diffpd_add_mpi_program_test name)
  list(JOIN ARGN "|" args)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DMPIEXEC=${MPIEXEC_EXECUTABLE} -DNUMPROC_FLAG=${MPIEXEC_NUMPROC_FLAG}
                   -DPROGRAM=$<TARGET_FILE:diffpd_mpi_cli> "-DARGS=${args}" -P ${_dir}/compare_rank_counts.cmake)
  set_tests_properties(${name} PROPERTIES ENVIRONMENT "${_mpi_env}")
endfunction()
diffpd_add_mpi_program_test(diffpd_mpi_train_starfish_ranks_test
                            train-starfish --starts 3 --small --steps 10 --evaluations 2 --json)
diffpd_add_mpi_program_test(diffpd_mpi_calibrate_starfish_ranks_test
                            calibrate-starfish --start 1.15 --seconds 0.15 --substeps 1 --max-iterations 2 --json)

# Bad input: exit status 2 and the message once, from rank 0, before any rollout.
function(diffpd_add_mpi_error_test name message)
  list(JOIN ARGN "|" args)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DMPIEXEC=${MPIEXEC_EXECUTABLE} -DNUMPROC_FLAG=${MPIEXEC_NUMPROC_FLAG}
                   -DPROGRAM=$<TARGET_FILE:diffpd_mpi_cli> "-DARGS=${args}" "-DMESSAGE=${message}"
                   -P ${_dir}/expect_error.cmake)
  set_tests_properties(${name} PROPERTIES ENVIRONMENT "${_mpi_env}")
endfunction()
diffpd_add_mpi_error_test(diffpd_mpi_refuses_bad_start_speed_test
                          "start speed = -1 is invalid: must be finite and >= 0" train-starfish --speed -1)
diffpd_add_mpi_error_test(diffpd_mpi_refuses_missing_recording_test
                          "DistributedRolloutSet: term 1 (rank 1): cannot open 'missing.csv'"
                          calibrate-starfish --recordings ${PROJECT_SOURCE_DIR}/../shared/data/starfish/data_horizontal_cyclic1.csv
                          missing.csv --seconds 0.1)
