# The optimiser side (solvers/), mirrored: the rollout core and each adapter.
include(${CMAKE_CURRENT_LIST_DIR}/core/tests.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/ceres/tests.cmake)
include(${CMAKE_CURRENT_LIST_DIR}/ipopt/tests.cmake)
