#include "solver/energy_bounded_step.h"

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {
// g's rounding relative to |g| allowed for (sums of (sigma - 1)^2 lose
// relative precision; measured up to 1.5e-12, solver/line_search.cc).
constexpr double kRoundingSlack = 1e-9;
}  // namespace

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
  // A converged result may sit above g(x_i) by the solve's tolerance (by
  // convexity near its minimum, g(x) - g(x*) <= |grad g(x)| |x - x*|) and by
  // g's rounding (x_i itself nearly optimal: a body at rest). Only a larger
  // excess is a far stationary point.
  const double slack =
      report->final_residual * (x - previous).norm() + kRoundingSlack * (std::abs(value) + std::abs(previous_value));
  if (value <= previous_value + slack) return x;
  // A stationary point above the previous total energy: descend from x_i.
  objective.SetReferenceResidual(report->initial_residual);
  StepReport again;
  x = solve(objective, previous, &again);
  AppendSolve(again, report);
  ++report->energy_restarts;
  return x;
}

}  // namespace diffpd::internal
