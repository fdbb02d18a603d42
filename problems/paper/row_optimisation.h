// A paper row optimised the way the paper's L-BFGS-B run is mapped here:
// Ipopt with a limited-memory Hessian (the row's history, maxcor) and the
// row's variable bounds, on the row's rollout function
// (row_rollout_function.h), from x_init, stopped as L-BFGS-B stops: when an
// iteration decreases the loss by at most ftol relative to its size
// ((f_k - f_k+1) / max(|f_k|, |f_k+1|, 1) <= ftol), after the row's evaluation
// budget (maxfun) or its iteration limit (maxiter); or at a wall-clock limit.
//
//   RowOptimisationOptions o;
//   o.budget_seconds = 600;
//   RowOptimisationResult r = OptimiseRow(row, row.Options(Method::kPdLbfgs, 2), o);
//
// Needs the Ipopt adapter (DIFFPD_WITH_IPOPT).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "diffpd/solver_options.h"
#include "diffpd/types.h"
#include "paper/paper_row.h"

namespace diffpd::problems {

struct RowOptimisationOptions {
  // Rollouts (loss evaluations) after which the optimiser stops; <= 0: the
  // row's budget (OptimizerBudget::max_evaluations).
  int max_evaluations = 0;
  // Wall-clock seconds after which the optimiser stops at its next
  // iteration; <= 0: none.
  double budget_seconds = 0;
  // Called after every new rollout with (evaluation number, loss, forward s);
  // may be empty.
  std::function<void(long, double, double)> on_evaluation;
};

struct RowOptimisationResult {
  std::string status;      // Ipopt's return status ("Solve_Succeeded", "User_Requested_Stop", ...)
  std::string stopped_by;  // "optimiser", "relative decrease", "evaluation budget" or "time budget"
  int iterations = 0;      // Ipopt iterations
  long evaluations = 0;    // rollouts (loss evaluations)
  long gradients = 0;      // adjoint passes
  long failed_evaluations = 0;
  double forward_s = 0;              // mean wall seconds per rollout
  double backward_s = 0;             // mean wall seconds per adjoint pass (with the pull-back)
  double total_s = 0;                // wall seconds of the whole optimisation
  double initial_loss = 0;           // L at x_init (NaN if its rollout failed)
  double final_loss = 0;             // L at the returned point (NaN if its rollout failed)
  VectorXd x;                        // the returned point
  std::vector<double> loss_history;  // L per Ipopt iteration (0 = start)
  std::string last_error;            // the latest failed evaluation's message, if any
};

// Throws InvalidInputError if the row still needs PaperRow::Prepare; never
// throws for a failed rollout (the optimiser cuts its step; last_error).
RowOptimisationResult OptimiseRow(const PaperRow& row, const SolverOptions& options,
                                  const RowOptimisationOptions& optimisation);

}  // namespace diffpd::problems
