// A material fit over a RolloutSet (diffpd/solvers/core/rollout_set.h): the
// terms' residual rows in one Ceres residual block, Levenberg-Marquardt with
// the calibration problems' settings (material_fit_settings.h). Run it on
// the rank that evaluates (rank 0 of a DistributedRolloutSet).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "diffpd/solvers/core/material_block.h"
#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::problems {

struct RolloutSetFit {
  std::vector<double> initial;  // starting values, in the fields' order
  std::vector<double> values;   // fitted values
  double initial_cost = 0;      // 1/2 |v|^2 over every term's rows
  double final_cost = 0;
  int iterations = 0;
  int evaluations = 0;  // set evaluations (residuals, with or without Jacobian)
  double seconds = 0;   // wall time of the solve
  bool usable = false;  // Ceres' solution is usable and its final cost finite
  std::string termination;
};

// `fields`: what the set's parameters are (their order). With a log, the
// iteration table goes there (nullptr: silent).
RolloutSetFit FitMaterialOverSet(solvers::RolloutSet* set, const std::vector<solvers::MaterialField>& fields,
                                 int max_iterations, FILE* log);

}  // namespace diffpd::problems
