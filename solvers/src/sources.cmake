# Sources of the optimiser adapters (paths relative to solvers/).
set(DIFFPD_SOLVERS_SOURCES ${CMAKE_CURRENT_LIST_DIR}/optimizer_versions.cc)
list(APPEND DIFFPD_SOLVERS_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/control_variables.cc
  ${CMAKE_CURRENT_LIST_DIR}/linear_constraint.cc
  ${CMAKE_CURRENT_LIST_DIR}/rollout_nlp.cc
  ${CMAKE_CURRENT_LIST_DIR}/ipopt_solve.cc)
# Ceres adapters (calibration).
list(APPEND DIFFPD_SOLVERS_SOURCES
  ${CMAKE_CURRENT_LIST_DIR}/calibration_model.cc
  ${CMAKE_CURRENT_LIST_DIR}/marker_cost_function.cc
  ${CMAKE_CURRENT_LIST_DIR}/rollout_loss_function.cc
  ${CMAKE_CURRENT_LIST_DIR}/coordinate_manifold.cc)
