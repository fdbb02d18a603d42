// The optimisers that train a swimmer's controller: each minimises the loss
// functional `loss` (one value) of a RolloutFunction over its parameters
// (the controller's weights, controller_block.h) from the parameters'
// starting values, within an EvaluationBudget that records the learning
// curve, and returns the final parameters. A failed evaluation counts
// against the budget; Adam stops at one (SolverError with the rollout
// function's message), the line-search methods cut their step.
#pragma once

#include <memory>
#include <string>

#include "control/adam.h"
#include "control/evaluation_budget.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::problems {

// Adam (adam.h): one evaluation with gradient per update, `budget` updates;
// the returned parameters are those after the last update (not evaluated).
VectorXd MinimizeWithAdam(solvers::RolloutFunction* function, int loss, const AdamOptions& options,
                          EvaluationBudget* budget);
// The same over a rollout set's scalar loss L(p) (RolloutSet::Gradient: the
// terms' losses summed), from the set's initial parameters; the same code
// whether the set is local or spread over MPI ranks (call it on rank 0).
// A failed evaluation throws SolverError with the set's last_error().
VectorXd MinimizeWithAdam(solvers::RolloutSet* set, const AdamOptions& options, EvaluationBudget* budget);

// Ceres' gradient solver (ceres::GradientProblemSolver, L-BFGS line search
// with strong Wolfe conditions) through solvers/ceres' RolloutLossFunction.
// Returns Ceres' final point and sets *report to Ceres' one-line report.
// Defined with the Ceres adapter only.
VectorXd MinimizeWithLbfgs(solvers::RolloutFunction* function, int loss, EvaluationBudget* budget, std::string* report);
// The same over a rollout set's scalar loss (solvers/ceres'
// RolloutSetLossFunction), from the set's initial parameters.
VectorXd MinimizeWithLbfgs(solvers::RolloutSet* set, EvaluationBudget* budget, std::string* report);

// Ipopt with a limited-memory Hessian through solvers/ipopt's RolloutNlp
// (which takes the function over). Returns Ipopt's final point (or the best
// point it evaluated, ipopt_solve.h) and sets *report to Ipopt's status.
// Defined with the Ipopt adapter only.
VectorXd MinimizeWithIpopt(std::unique_ptr<solvers::RolloutFunction> function, int loss, EvaluationBudget* budget,
                           std::string* report);
// The same over a rollout set's scalar loss (solvers/ipopt's RolloutSetNlp),
// from the set's initial parameters.
VectorXd MinimizeWithIpopt(solvers::RolloutSet* set, EvaluationBudget* budget, std::string* report);

}  // namespace diffpd::problems
