#include "calibration/rollout_set_fit.h"

#include <chrono>
#include <cmath>

#include <ceres/ceres.h>

#include "calibration/counting_cost_function.h"
#include "calibration/iteration_table.h"
#include "calibration/material_fit_settings.h"

namespace diffpd::problems {

RolloutSetFit FitMaterialOverSet(solvers::RolloutSet* set, const std::vector<solvers::MaterialField>& fields,
                                 int max_iterations, FILE* log) {
  RolloutSetFit fit;
  const VectorXd start = set->initial_parameters();
  std::vector<double> block(start.data(), start.data() + start.size());
  fit.initial = block;
  ceres::Problem problem;
  problem.AddResidualBlock(new CountingCostFunction(set, &fit.evaluations), nullptr, block.data());
  SetMaterialCoordinates(&problem, block.data(), fields);
  ceres::Solver::Options options = MaterialFitOptions(max_iterations);
  IterationTable table(log, fields, block.data());
  if (log) options.callbacks.push_back(&table);
  ceres::Solver::Summary summary;
  const auto begin = std::chrono::steady_clock::now();
  ceres::Solve(options, &problem, &summary);
  fit.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  fit.values = block;
  fit.initial_cost = summary.initial_cost;
  fit.final_cost = summary.final_cost;
  fit.iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit.usable =
      summary.IsSolutionUsable() && summary.termination_type != ceres::FAILURE && std::isfinite(summary.final_cost);
  fit.termination = summary.message;
  if (!set->last_error().empty()) fit.termination += "; last failed evaluation: " + set->last_error();
  return fit;
}

}  // namespace diffpd::problems
