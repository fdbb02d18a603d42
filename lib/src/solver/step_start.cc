#include "solver/step_start.h"

#include "diffpd/error.h"

namespace diffpd::internal {

VectorXd ChooseStepStart(StepObjective& objective, const VectorXd& predicted, const VectorXd& previous) {
  if (!objective.sim().options.start_at_lower_energy) return predicted;
  VectorXd predicted_grad;
  const double predicted_value = objective.Evaluate(predicted, &predicted_grad);
  objective.SetReferenceResidual(predicted_grad.norm());
  VectorXd previous_grad;
  double previous_value = 0;
  try {
    previous_value = objective.Evaluate(previous, &previous_grad);
  } catch (const SolverError& e) {
    if (e.status() != SolverStatus::kNonFinite && e.status() != SolverStatus::kInvertedElement) throw;
    objective.Prime(predicted, predicted_value, predicted_grad);
    return predicted;
  }
  if (previous_value < predicted_value) {
    objective.Prime(previous, previous_value, previous_grad);
    return previous;
  }
  objective.Prime(predicted, predicted_value, predicted_grad);
  return predicted;
}

}  // namespace diffpd::internal
