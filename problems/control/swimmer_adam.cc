#include <functional>
#include <string>

#include "control/swimmer_optimizers.h"
#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

// Adam's loop over a loss given by its gradient: gradient(theta, &g, &value)
// false on failure, with the reason from error().
VectorXd AdamLoop(VectorXd theta, const std::function<bool(const VectorXd&, VectorXd*, double*)>& gradient,
                  const std::function<std::string()>& error, const AdamOptions& options, EvaluationBudget* budget) {
  Adam adam(options, static_cast<int>(theta.size()));
  VectorXd g;
  while (budget->Admit(theta) && budget->used() < budget->budget()) {
    double value = 0;
    const bool ok = gradient(theta, &g, &value);
    budget->Record(theta, ok, value, ok ? &g : nullptr);
    if (!ok) throw SolverError(SolverStatus::kNonFinite, error());
    adam.Step(g, &theta);
  }
  return theta;
}

}  // namespace

VectorXd MinimizeWithAdam(solvers::RolloutFunction* function, int loss, const AdamOptions& options,
                          EvaluationBudget* budget) {
  VectorXd weights = VectorXd::Zero(function->num_rows());
  weights(function->functional_row(loss)) = 1;
  return AdamLoop(
      function->initial_parameters(),
      [&](const VectorXd& theta, VectorXd* g, double* value) { return function->Gradient(theta, weights, g, value); },
      [&] { return function->statistics().last_error; }, options, budget);
}

VectorXd MinimizeWithAdam(solvers::RolloutSet* set, const AdamOptions& options, EvaluationBudget* budget) {
  return AdamLoop(
      set->initial_parameters(),
      [&](const VectorXd& theta, VectorXd* g, double* value) { return set->Gradient(theta, g, value); },
      [&] { return set->last_error(); }, options, budget);
}

}  // namespace diffpd::problems
