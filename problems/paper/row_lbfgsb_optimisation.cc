// A paper row optimised by L-BFGS-B with the row's scipy settings.
#include <chrono>
#include <cmath>
#include <utility>

#include "diffpd/solvers/lbfgsb/lbfgsb.h"
#include "paper/row_optimisers.h"
#include "paper/row_rollout_function.h"

namespace diffpd::problems {

RowOptimisationResult OptimiseRowWithLbfgsb(const PaperRow& row, const SolverOptions& options,
                                            const RowOptimisationOptions& optimisation) {
  using Clock = std::chrono::steady_clock;
  RowRolloutFunction f = MakeRowRolloutFunction(row, options);
  solvers::RolloutFunction& function = *f.function;
  VectorXd weights = VectorXd::Zero(function.num_rows());
  for (size_t t = 0; t < f.loss_rows.size(); ++t) weights(f.loss_rows[t]) += f.loss_weights[t];

  // Every new rollout is reported with its loss and its forward seconds.
  long reported = 0;
  double reported_seconds = 0;
  const solvers::LbfgsbObjective objective = [&](const VectorXd& x, double* loss, VectorXd* gradient) {
    const bool ok = function.Gradient(x, weights, gradient, loss);
    const solvers::RolloutStatistics& stats = function.statistics();
    if (optimisation.on_evaluation && stats.rollouts > reported) {
      optimisation.on_evaluation(stats.rollouts, ok ? *loss : std::nan(""), stats.forward_seconds - reported_seconds);
      reported = stats.rollouts;
      reported_seconds = stats.forward_seconds;
    }
    return ok;
  };
  const auto start = Clock::now();
  solvers::LbfgsbOptions o;
  o.memory = row.budget.history;
  o.ftol = row.budget.ftol;
  o.pgtol = row.budget.gtol;
  o.max_iterations = row.budget.max_iterations;
  o.max_evaluations = optimisation.max_evaluations > 0 ? optimisation.max_evaluations : row.budget.max_evaluations;
  o.on_iteration = [&](const solvers::LbfgsbIteration&, const VectorXd&, const VectorXd&) {
    return optimisation.budget_seconds <= 0 ||
           std::chrono::duration<double>(Clock::now() - start).count() < optimisation.budget_seconds;
  };
  const solvers::LbfgsbResult r =
      solvers::MinimizeLbfgsb(objective, row.initial(), function.lower_bounds(), function.upper_bounds(), o);

  RowOptimisationResult out;
  out.optimizer = ToString(RowOptimizer::kLbfgsb);
  out.total_s = std::chrono::duration<double>(Clock::now() - start).count();
  out.status = solvers::ToString(r.stop);
  switch (r.stop) {
    case solvers::LbfgsbStop::kRelativeReduction:
      out.stopped_by = "relative decrease";
      break;
    case solvers::LbfgsbStop::kMaxEvaluations:
      out.stopped_by = "evaluation budget";
      break;
    case solvers::LbfgsbStop::kMaxIterations:
      out.stopped_by = "iteration limit";
      break;
    case solvers::LbfgsbStop::kCallback:
      out.stopped_by = "time budget";
      break;
    default:
      out.stopped_by = "optimiser";
  }
  out.iterations = r.iterations;
  const solvers::RolloutStatistics& stats = function.statistics();
  out.evaluations = stats.rollouts;
  out.failed_evaluations = r.failed_evaluations;
  out.gradients = stats.adjoint_passes;
  out.forward_s = stats.rollouts > 0 ? stats.forward_seconds / stats.rollouts : 0;
  out.backward_s = stats.adjoint_passes > 0 ? stats.backward_seconds / stats.adjoint_passes : 0;
  out.initial_loss = r.history.empty() ? std::nan("") : r.history.front().f;
  out.final_loss = r.f;
  out.x = r.x;
  for (const solvers::LbfgsbIteration& it : r.history) out.loss_history.push_back(it.f);
  // The rollout function's reason is the specific one ("rollout failed (...)").
  out.last_error = stats.last_error.empty() ? r.last_error : stats.last_error;
  return out;
}

}  // namespace diffpd::problems
