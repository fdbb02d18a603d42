#include "paper/row_optimisers.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <utility>

#include "diffpd/solvers/ipopt/ipopt_solve.h"
#include "diffpd/solvers/ipopt/rollout_nlp.h"
#include "paper/row_rollout_function.h"

namespace diffpd::problems {
namespace {

using Clock = std::chrono::steady_clock;

// The row's NLP, stopped by L-BFGS-B's relative-decrease test, the
// evaluation budget and the time budget (Ipopt's intermediate_callback
// returning false), reporting every new rollout.
class BudgetedRowNlp : public solvers::RolloutNlp {
 public:
  BudgetedRowNlp(std::unique_ptr<solvers::RolloutFunction> function, double ftol, long max_evaluations,
                 double budget_seconds, std::function<void(long, double, double)> on_evaluation)
      : RolloutNlp(std::move(function)),
        ftol_(ftol),
        max_evaluations_(max_evaluations),
        budget_seconds_(budget_seconds),
        on_evaluation_(std::move(on_evaluation)),
        start_(Clock::now()) {}

  bool eval_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number& obj_value) override {
    const bool ok = RolloutNlp::eval_f(n, x, new_x, obj_value);
    ReportNewRollout(Eigen::Map<const VectorXd>(x, n));
    return ok;
  }
  bool eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool new_x, Ipopt::Number* grad_f) override {
    const bool ok = RolloutNlp::eval_grad_f(n, x, new_x, grad_f);
    ReportNewRollout(Eigen::Map<const VectorXd>(x, n));
    return ok;
  }

  // Reports the latest rollout (at x) if one was made since the last report:
  // its number, the loss there (cached) and the forward seconds since.
  void ReportNewRollout(const VectorXd& x) {
    if (!on_evaluation_ || statistics().rollouts <= reported_) return;
    double loss = std::nan("");
    if (!Objective(x, &loss)) loss = std::nan("");
    on_evaluation_(statistics().rollouts, loss, statistics().forward_seconds - reported_seconds_);
    reported_ = statistics().rollouts;
    reported_seconds_ = statistics().forward_seconds;
  }

  bool intermediate_callback(Ipopt::AlgorithmMode mode, Ipopt::Index iter, Ipopt::Number obj_value,
                             Ipopt::Number inf_pr, Ipopt::Number inf_du, Ipopt::Number mu, Ipopt::Number d_norm,
                             Ipopt::Number regularization_size, Ipopt::Number alpha_du, Ipopt::Number alpha_pr,
                             Ipopt::Index ls_trials, const Ipopt::IpoptData* ip_data,
                             Ipopt::IpoptCalculatedQuantities* ip_cq) override {
    RolloutNlp::intermediate_callback(mode, iter, obj_value, inf_pr, inf_du, mu, d_norm, regularization_size, alpha_du,
                                      alpha_pr, ls_trials, ip_data, ip_cq);
    // L-BFGS-B's test, (f_k - f_k+1) / max(|f_k|, |f_k+1|, 1) <= ftol, on
    // the change of f between Ipopt iterations (an increase, which an
    // interior-point iteration may make, does not stop it).
    const double decrease = previous_objective_ - obj_value;
    const bool stalled = iter > 0 && decrease >= 0 &&
                         decrease <= ftol_ * std::max({std::abs(previous_objective_), std::abs(obj_value), 1.0});
    previous_objective_ = obj_value;
    if (stalled) {
      stopped_by_ = "relative decrease";
      return false;
    }
    if (statistics().rollouts >= max_evaluations_) {
      stopped_by_ = "evaluation budget";
      return false;
    }
    if (budget_seconds_ > 0 && std::chrono::duration<double>(Clock::now() - start_).count() >= budget_seconds_) {
      stopped_by_ = "time budget";
      return false;
    }
    return true;
  }

  const std::string& stopped_by() const { return stopped_by_; }

 private:
  double ftol_;
  long max_evaluations_;
  double budget_seconds_;
  double previous_objective_ = 0;
  std::function<void(long, double, double)> on_evaluation_;
  Clock::time_point start_;
  std::string stopped_by_ = "optimiser";
  long reported_ = 0;
  double reported_seconds_ = 0;
};

}  // namespace

RowOptimisationResult OptimiseRowWithIpopt(const PaperRow& row, const SolverOptions& options,
                                           const RowOptimisationOptions& optimisation) {
  RowRolloutFunction f = MakeRowRolloutFunction(row, options);
  const long max_evaluations =
      optimisation.max_evaluations > 0 ? optimisation.max_evaluations : row.budget.max_evaluations;
  Ipopt::SmartPtr<BudgetedRowNlp> nlp = new BudgetedRowNlp(std::move(f.function), row.budget.ftol, max_evaluations,
                                                           optimisation.budget_seconds, optimisation.on_evaluation);
  // One objective term per loss term (each functional has one row).
  for (size_t t = 0; t < f.loss_rows.size(); ++t) nlp->AddObjectiveRows({f.loss_rows[t]}, f.loss_weights[t]);
  nlp->SetStartingPoint(row.initial());
  // The first evaluation, at x_init, here so that it is reported too
  // (SolveWithIpopt's own evaluation there then hits the rollout cache).
  double loss0 = 0;
  nlp->Objective(row.initial(), &loss0);
  nlp->ReportNewRollout(row.initial());

  solvers::IpoptOptions ipopt;
  ipopt.int_options = {
      {"print_level", 0}, {"max_iter", row.budget.max_iterations}, {"limited_memory_max_history", row.budget.history}};
  ipopt.num_options = {{"tol", row.budget.gtol}};
  const auto start = Clock::now();
  const solvers::IpoptSummary summary = solvers::SolveWithIpopt(nlp, ipopt);
  nlp->ReportNewRollout(summary.x);

  RowOptimisationResult out;
  out.optimizer = ToString(RowOptimizer::kIpopt);
  out.total_s = std::chrono::duration<double>(Clock::now() - start).count();
  out.status = summary.status_name;
  out.stopped_by = nlp->stopped_by();
  if (summary.status == Ipopt::Maximum_Iterations_Exceeded) out.stopped_by = "iteration limit";
  out.iterations = summary.iterations;
  const solvers::RolloutStatistics& stats = nlp->statistics();
  out.evaluations = stats.rollouts;
  out.failed_evaluations = stats.failed_rollouts;
  out.gradients = stats.adjoint_passes;
  out.forward_s = stats.rollouts > 0 ? stats.forward_seconds / stats.rollouts : 0;
  out.backward_s = stats.adjoint_passes > 0 ? stats.backward_seconds / stats.adjoint_passes : 0;
  out.initial_loss = summary.initial_objective;
  out.final_loss = summary.objective;
  out.x = summary.x;
  out.loss_history = summary.objective_history;
  out.last_error = summary.last_error;
  return out;
}

}  // namespace diffpd::problems
