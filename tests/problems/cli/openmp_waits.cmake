# The diffpd program runs its OpenMP threads with a short spin unless the user
# chose the waits: run PROGRAM (a small table) without OMP_WAIT_POLICY and
# GOMP_SPINCOUNT and expect GOMP_SPINCOUNT=SPIN in the table's machine label;
# run it with OMP_WAIT_POLICY=active and expect that alone.
#   cmake -DPROGRAM=diffpd -DSPIN=1000 -P openmp_waits.cmake
set(table table --small --rows cantilever --methods pd-lbfgs --draws 0 --evaluations 1 --threads 2)

# Runs the table with the environment changes given after LABEL (for `cmake -E env`)
# and fails unless its machine label ends with LABEL.
function(expect_label label)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env ${ARGN} ${PROGRAM} ${table}
                  OUTPUT_VARIABLE out ERROR_VARIABLE err RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "exit status ${rc}\n${err}")
  endif()
  string(FIND "${out}" ", ${label}, 2 threads" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "expected ${label} alone in the machine label, got:\n${out}")
  endif()
endfunction()

expect_label("GOMP_SPINCOUNT=${SPIN}" --unset=OMP_WAIT_POLICY --unset=GOMP_SPINCOUNT)
expect_label("OMP_WAIT_POLICY=active" --unset=GOMP_SPINCOUNT OMP_WAIT_POLICY=active)
