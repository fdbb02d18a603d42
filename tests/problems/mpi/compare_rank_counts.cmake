# Runs PROGRAM with ARGS (separated by |) on 1 and on 2 MPI ranks and fails unless
# both print a JSON report, exit alike, and the reports are equal once their
# "run" members (ranks, threads, seconds) are removed. The doubles are
# printed to round-trip precision, so equal text is equal bits.
#   cmake -DMPIEXEC=mpiexec -DNUMPROC_FLAG=-n -DPROGRAM=diffpd-mpi "-DARGS=a|b" -P compare_rank_counts.cmake
string(REPLACE "|" ";" ARGS "${ARGS}")
foreach(ranks 1 2)
  execute_process(COMMAND ${MPIEXEC} ${NUMPROC_FLAG} ${ranks} --oversubscribe ${PROGRAM} ${ARGS}
                  OUTPUT_VARIABLE out_${ranks} ERROR_VARIABLE err_${ranks} RESULT_VARIABLE rc_${ranks})
  if(NOT rc_${ranks} MATCHES "^[05]$")
    message(FATAL_ERROR "${ranks} rank(s): exit status ${rc_${ranks}}\n${err_${ranks}}")
  endif()
  string(JSON report_${ranks} ERROR_VARIABLE json_error REMOVE "${out_${ranks}}" run)
  if(json_error)
    message(FATAL_ERROR "${ranks} rank(s): no JSON report (${json_error}):\n${out_${ranks}}\n${err_${ranks}}")
  endif()
  string(JSON ranks_reported GET "${out_${ranks}}" run ranks)
  if(NOT ranks_reported EQUAL ranks)
    message(FATAL_ERROR "${ranks} rank(s): the report says ${ranks_reported} ranks")
  endif()
endforeach()
if(NOT rc_1 EQUAL rc_2)
  message(FATAL_ERROR "exit status ${rc_1} on 1 rank, ${rc_2} on 2 ranks")
endif()
if(NOT report_1 STREQUAL report_2)
  message(FATAL_ERROR "the reports differ:\n1 rank:\n${report_1}\n2 ranks:\n${report_2}")
endif()
message(STATUS "1 and 2 ranks report alike:\n${report_2}")
