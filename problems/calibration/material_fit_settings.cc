#include "calibration/material_fit_settings.h"

#include "diffpd/solvers/ceres/coordinate_manifold.h"

namespace diffpd::problems {

void SetMaterialCoordinates(ceres::Problem* problem, double* block, const std::vector<solvers::MaterialField>& fields) {
  std::vector<solvers::CoordinateMap> maps;
  for (solvers::MaterialField field : fields)
    maps.push_back(field == solvers::MaterialField::kPoissonsRatio ? solvers::CoordinateMap::Linear()
                                                                   : solvers::CoordinateMap::Log());
  problem->SetManifold(block, new solvers::CoordinateManifold(maps));
  for (size_t i = 0; i < fields.size(); ++i)
    if (fields[i] == solvers::MaterialField::kPoissonsRatio) {
      problem->SetParameterLowerBound(block, static_cast<int>(i), 0.01);
      problem->SetParameterUpperBound(block, static_cast<int>(i), 0.49);
    }
}

ceres::Solver::Options MaterialFitOptions(int max_iterations) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = max_iterations;
  options.function_tolerance = 1e-9;   // above the forward solves' noise
  options.parameter_tolerance = 1e-6;  // relative: far below the noise's effect
  options.gradient_tolerance = 1e-14;
  options.update_state_every_iteration = true;
  options.logging_type = ceres::SILENT;
  return options;
}

}  // namespace diffpd::problems
