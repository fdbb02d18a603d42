// A paper row optimised as the paper did: by L-BFGS-B (solvers/lbfgsb, the
// optimiser of the paper's scipy runs) with the row's history (maxcor),
// ftol, pgtol (gtol), iteration limit (maxiter) and evaluation budget
// (maxfun), and the row's variable bounds, on the row's rollout function
// (row_rollout_function.h), from x_init projected onto the bounds; or by
// Ipopt with a limited-memory Hessian and the same bounds, stopped by
// L-BFGS-B's relative-decrease test ((f_k - f_k+1) / max(|f_k|, |f_k+1|, 1)
// <= ftol between its iterations), the budget or the iteration limit. Both
// also stop at a wall-clock limit.
//
//   RowOptimisationOptions o;
//   o.budget_seconds = 600;
//   RowOptimisationResult r = OptimiseRow(row, row.Options(Method::kPdLbfgs, 2), o);
//
// Ipopt needs the Ipopt adapter (DIFFPD_WITH_IPOPT).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "diffpd/solver_options.h"
#include "diffpd/types.h"
#include "paper/paper_row.h"

namespace diffpd::problems {

// The optimiser of a row: "lbfgsb" or "ipopt".
enum class RowOptimizer { kLbfgsb, kIpopt };
const char* ToString(RowOptimizer optimizer);
// Throws InvalidInputError: "optimizer 'bfgs' is unknown: use lbfgsb or ipopt".
RowOptimizer ParseRowOptimizer(const std::string& name);

struct RowOptimisationOptions {
  RowOptimizer optimizer = RowOptimizer::kLbfgsb;
  // Rollouts (loss evaluations) after which the optimiser stops; <= 0: the
  // row's budget (OptimizerBudget::max_evaluations). L-BFGS-B tests it
  // between iterations as scipy does (it stops once more were made), Ipopt
  // at its next iteration.
  int max_evaluations = 0;
  // Wall-clock seconds after which the optimiser stops at its next
  // iteration; <= 0: none.
  double budget_seconds = 0;
  // Called after every new rollout with (evaluation number, loss, forward s);
  // may be empty.
  std::function<void(long, double, double)> on_evaluation;
};

struct RowOptimisationResult {
  std::string optimizer;  // ToString(RowOptimizer)
  // L-BFGS-B's stop (ToString(LbfgsbStop): "relative reduction <= ftol", ...)
  // or Ipopt's return status ("Solve_Succeeded", "User_Requested_Stop", ...).
  std::string status;
  // "relative decrease", "evaluation budget", "iteration limit", "time budget"
  // or "optimiser" (its own test: projected gradient, a failed line search).
  std::string stopped_by;
  int iterations = 0;    // the optimiser's iterations
  long evaluations = 0;  // rollouts (loss evaluations)
  long gradients = 0;    // adjoint passes
  long failed_evaluations = 0;
  double forward_s = 0;              // mean wall seconds per rollout
  double backward_s = 0;             // mean wall seconds per adjoint pass (with the pull-back)
  double total_s = 0;                // wall seconds of the whole optimisation
  double initial_loss = 0;           // L at x_init (NaN if its rollout failed)
  double final_loss = 0;             // L at the returned point (NaN if its rollout failed)
  VectorXd x;                        // the returned point
  std::vector<double> loss_history;  // L per iteration (0 = start)
  std::string last_error;            // the latest failed evaluation's message, if any
};

// Throws InvalidInputError if the row still needs PaperRow::Prepare or Ipopt
// is asked for in a build without it ("optimizer ipopt: this build has no
// Ipopt adapter (configure with DIFFPD_WITH_IPOPT=ON)"); never throws for a
// failed rollout (the optimiser cuts its step; last_error).
RowOptimisationResult OptimiseRow(const PaperRow& row, const SolverOptions& options,
                                  const RowOptimisationOptions& optimisation);

}  // namespace diffpd::problems
