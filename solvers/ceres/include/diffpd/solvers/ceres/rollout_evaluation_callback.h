// Runs a RolloutFunction's rollout (and, when Ceres asks for Jacobians, the
// Jacobian rows) once per evaluation point, reading the point from the
// user's parameter blocks, before Ceres evaluates the cost functions
// (rollout_cost_function.h). Failures are recorded in the function; the cost
// functions then return false.
#pragma once

#include <vector>

#include <ceres/evaluation_callback.h>

#include "diffpd/solvers/core/rollout_function.h"

namespace diffpd::solvers {

class RolloutEvaluationCallback : public ceres::EvaluationCallback {
 public:
  // `blocks`: the parameter blocks given to the residual blocks, one per
  // parameter block of `function`, in its order; `rows`: the rows whose
  // Jacobian to prepare (empty: every row). Does not take ownership of
  // anything. Throws InvalidInputError if the number of blocks is not the
  // function's ("RolloutEvaluationCallback: got 2 parameter blocks, the
  // rollout function has 1").
  RolloutEvaluationCallback(RolloutFunction* function, std::vector<double*> blocks, std::vector<int> rows = {});
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

 private:
  RolloutFunction* function_;
  std::vector<double*> blocks_;
  std::vector<int> rows_;
  MatrixXd scratch_;
};

}  // namespace diffpd::solvers
