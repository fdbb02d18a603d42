#include "control/swimmer_optimizers.h"

#include "diffpd/error.h"

namespace diffpd::problems {

VectorXd MinimizeWithAdam(solvers::RolloutFunction* function, int loss, const AdamOptions& options,
                          EvaluationBudget* budget) {
  Adam adam(options, function->num_parameters());
  VectorXd weights = VectorXd::Zero(function->num_rows());
  weights(function->functional_row(loss)) = 1;
  VectorXd theta = function->initial_parameters(), gradient;
  while (budget->Admit(theta) && budget->used() < budget->budget()) {
    double value = 0;
    const bool ok = function->Gradient(theta, weights, &gradient, &value);
    budget->Record(theta, ok, value, ok ? &gradient : nullptr);
    if (!ok) throw SolverError(SolverStatus::kNonFinite, function->statistics().last_error);
    adam.Step(gradient, &theta);
  }
  return theta;
}

}  // namespace diffpd::problems
