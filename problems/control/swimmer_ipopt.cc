#include <utility>

#include "control/swimmer_optimizers.h"
#include "diffpd/solvers/ipopt/ipopt_solve.h"
#include "diffpd/solvers/ipopt/rollout_nlp.h"
#include "diffpd/solvers/ipopt/rollout_set_nlp.h"

namespace diffpd::problems {
namespace {

// An NLP (RolloutNlp or RolloutSetNlp) within the budget: a point beyond it
// is a failed evaluation (Ipopt cuts its step) and the next iteration stops
// the solve.
template <typename Nlp>
class BudgetedNlp : public Nlp {
 public:
  template <typename Source>
  BudgetedNlp(Source&& source, EvaluationBudget* budget) : Nlp(std::forward<Source>(source)), budget_(budget) {}
  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number& obj_value) override {
    const Eigen::Map<const VectorXd> p(x, n);
    if (!budget_->Admit(p)) return false;
    const bool ok = Nlp::eval_f(n, x, new_x, obj_value);
    budget_->Record(p, ok, ok ? obj_value : 0.0, nullptr);
    return ok;
  }
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number* grad_f) override {
    const Eigen::Map<const VectorXd> p(x, n);
    if (!budget_->Admit(p)) return false;
    double value = 0;
    const bool ok = Nlp::eval_grad_f(n, x, new_x, grad_f) && Nlp::eval_f(n, x, false, value);
    const VectorXd g = ok ? VectorXd(Eigen::Map<const VectorXd>(grad_f, n)) : VectorXd();
    budget_->Record(p, ok, value, ok ? &g : nullptr);
    return ok;
  }
  bool intermediate_callback(Ipopt::AlgorithmMode mode, Ipopt::Index iter, Ipopt::Number obj_value,
                             Ipopt::Number inf_pr, Ipopt::Number inf_du, Ipopt::Number mu, Ipopt::Number d_norm,
                             Ipopt::Number regularization_size, Ipopt::Number alpha_du, Ipopt::Number alpha_pr,
                             Ipopt::Index ls_trials, const Ipopt::IpoptData* ip_data,
                             Ipopt::IpoptCalculatedQuantities* ip_cq) override {
    const bool go_on = Nlp::intermediate_callback(mode, iter, obj_value, inf_pr, inf_du, mu, d_norm,
                                                  regularization_size, alpha_du, alpha_pr, ls_trials, ip_data, ip_cq);
    return go_on && !budget_->exhausted() && budget_->used() < budget_->budget();
  }

 private:
  EvaluationBudget* budget_;
};

// Silent, at most the budget's iterations; only the budget ends the
// training (the loss has no known minimum).
solvers::IpoptOptions TrainingOptions(const EvaluationBudget& budget) {
  solvers::IpoptOptions options;
  options.int_options.push_back({"print_level", 0});
  options.int_options.push_back({"max_iter", budget.budget()});
  options.num_options.push_back({"tol", 1e-12});
  return options;
}

}  // namespace

VectorXd MinimizeWithIpopt(std::unique_ptr<solvers::RolloutFunction> function, int loss, EvaluationBudget* budget,
                           std::string* report) {
  const std::vector<int> rows = function->RowsOf(loss);
  Ipopt::SmartPtr<BudgetedNlp<solvers::RolloutNlp>> nlp =
      new BudgetedNlp<solvers::RolloutNlp>(std::move(function), budget);
  nlp->AddObjectiveRows(rows);
  const solvers::IpoptSummary summary =
      solvers::SolveWithIpopt(Ipopt::SmartPtr<solvers::RolloutNlp>(nlp), TrainingOptions(*budget));
  *report = summary.status_name;
  return summary.x;
}

VectorXd MinimizeWithIpopt(solvers::RolloutSet* set, EvaluationBudget* budget, std::string* report) {
  Ipopt::SmartPtr<BudgetedNlp<solvers::RolloutSetNlp>> nlp = new BudgetedNlp<solvers::RolloutSetNlp>(set, budget);
  const solvers::IpoptSummary summary =
      solvers::SolveRolloutSetWithIpopt(Ipopt::SmartPtr<solvers::RolloutSetNlp>(nlp), TrainingOptions(*budget));
  *report = summary.status_name;
  return summary.x;
}

}  // namespace diffpd::problems
