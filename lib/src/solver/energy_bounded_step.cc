#include "solver/energy_bounded_step.h"

#include "diffpd/error.h"

namespace diffpd::internal {

VectorXd SolveEnergyBounded(StepObjective& objective, const VectorXd& predicted, const VectorXd& previous,
                            const ImplicitSolver& solve, StepReport* report) {
  VectorXd x = solve(objective, predicted, report);
  // A solve paused at the objective's checkpoint (contact screening) is not
  // a result yet.
  if (!objective.sim().options.bound_step_energy || objective.checkpoint_stopped()) return x;
  double value = 0;
  if (!objective.LastValueAt(x, &value)) value = objective.Evaluate(x, nullptr);
  double previous_value = 0;
  try {
    previous_value = objective.Evaluate(previous, nullptr);
  } catch (const SolverError& e) {
    if (e.status() != SolverStatus::kNonFinite && e.status() != SolverStatus::kInvertedElement) throw;
    return x;
  }
  if (value <= previous_value) return x;
  // A stationary point above the previous total energy: descend from x_i.
  objective.SetReferenceResidual(report->initial_residual);
  StepReport again;
  x = solve(objective, previous, &again);
  report->iterations += again.iterations;
  report->line_search_steps += again.line_search_steps;
  report->final_residual = again.final_residual;
  ++report->energy_restarts;
  return x;
}

}  // namespace diffpd::internal
