# The optimiser side (solvers/), mirrored: the rollout core, the L-BFGS-B
# minimiser and each adapter that is built.
include(${CMAKE_CURRENT_LIST_DIR}/core/tests.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/lbfgsb/tests.cmake)
if(TARGET diffpd_ceres)
  include(${CMAKE_CURRENT_LIST_DIR}/ceres/tests.cmake)
endif()
if(TARGET diffpd_ipopt)
  include(${CMAKE_CURRENT_LIST_DIR}/ipopt/tests.cmake)
endif()
if(TARGET diffpd_mpi)
  include(${CMAKE_CURRENT_LIST_DIR}/mpi/tests.cmake)
endif()
