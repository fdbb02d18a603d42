# The bound-constrained L-BFGS minimiser (solvers/lbfgsb/).
set(_dir ${CMAKE_CURRENT_LIST_DIR})
diffpd_add_test(lbfgsb_test ${_dir}/lbfgsb_test.cc LIBS diffpd_lbfgsb)
