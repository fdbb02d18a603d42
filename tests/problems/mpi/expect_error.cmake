# Runs PROGRAM with ARGS (separated by |) on 2 MPI ranks and fails unless it
# exits with status 2 and rank 0's stderr holds "diffpd-mpi: error: MESSAGE"
# exactly once (the other rank stays silent).
#   cmake -DMPIEXEC=mpiexec -DNUMPROC_FLAG=-n -DPROGRAM=diffpd-mpi "-DARGS=a|b" "-DMESSAGE=..." -P expect_error.cmake
string(REPLACE "|" ";" ARGS "${ARGS}")
execute_process(COMMAND ${MPIEXEC} ${NUMPROC_FLAG} 2 --oversubscribe ${PROGRAM} ${ARGS}
                OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
if(NOT rc EQUAL 2)
  message(FATAL_ERROR "exit status ${rc}, expected 2\n${err}")
endif()
set(expected "diffpd-mpi: error: ${MESSAGE}\n")
string(FIND "${err}" "${expected}" first)
string(FIND "${err}" "${expected}" last REVERSE)
if(first EQUAL -1 OR NOT first EQUAL last)
  message(FATAL_ERROR "expected \"${expected}\" once on stderr, got:\n${err}")
endif()
