#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>
#include <ceres/iteration_callback.h>

#include <utility>

#include "control/swimmer_optimizers.h"
#include "diffpd/solvers/ceres/rollout_loss_function.h"
#include "diffpd/solvers/ceres/rollout_set_loss_function.h"

namespace diffpd::problems {
namespace {

// A loss (RolloutLossFunction or RolloutSetLossFunction) within the
// budget: a point beyond it is a failed evaluation (Ceres cuts its step and,
// at the next iteration, stops).
template <typename Loss>
class BudgetedLoss : public ceres::FirstOrderFunction {
 public:
  template <typename... Args>
  BudgetedLoss(EvaluationBudget* budget, Args&&... args)
      : inner_(std::forward<Args>(args)...), n_(inner_.NumParameters()), budget_(budget) {}
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    const Eigen::Map<const VectorXd> p(parameters, n_);
    if (!budget_->Admit(p)) return false;
    const bool ok = inner_.Evaluate(parameters, cost, gradient);
    VectorXd g;
    if (ok && gradient) g = Eigen::Map<const VectorXd>(gradient, n_);
    budget_->Record(p, ok, ok ? *cost : 0.0, ok && gradient ? &g : nullptr);
    return ok;
  }
  int NumParameters() const override { return n_; }

 private:
  Loss inner_;
  int n_;
  EvaluationBudget* budget_;
};

class StopWhenSpent : public ceres::IterationCallback {
 public:
  explicit StopWhenSpent(const EvaluationBudget* budget) : budget_(budget) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return budget_->exhausted() || budget_->used() >= budget_->budget() ? ceres::SOLVER_TERMINATE_SUCCESSFULLY
                                                                        : ceres::SOLVER_CONTINUE;
  }

 private:
  const EvaluationBudget* budget_;
};

// Ceres' L-BFGS on `loss` (owned by the problem) from x0 within the budget.
VectorXd Lbfgs(ceres::FirstOrderFunction* loss, VectorXd x, EvaluationBudget* budget, std::string* report) {
  ceres::GradientProblem problem(loss);
  StopWhenSpent stop(budget);
  ceres::GradientProblemSolver::Options options;
  options.line_search_direction_type = ceres::LBFGS;
  options.max_num_iterations = budget->budget();
  // Only the budget ends the training (the loss has no known minimum).
  options.function_tolerance = 0;
  options.gradient_tolerance = 0;
  options.parameter_tolerance = 0;
  options.logging_type = ceres::SILENT;
  options.callbacks.push_back(&stop);
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(options, problem, x.data(), &summary);
  *report = summary.BriefReport();
  return x;
}

}  // namespace

VectorXd MinimizeWithLbfgs(solvers::RolloutFunction* function, int loss, EvaluationBudget* budget,
                           std::string* report) {
  return Lbfgs(new BudgetedLoss<solvers::RolloutLossFunction>(budget, function, loss), function->initial_parameters(),
               budget, report);
}

VectorXd MinimizeWithLbfgs(solvers::RolloutSet* set, EvaluationBudget* budget, std::string* report) {
  return Lbfgs(new BudgetedLoss<solvers::RolloutSetLossFunction>(budget, set), set->initial_parameters(), budget,
               report);
}

}  // namespace diffpd::problems
