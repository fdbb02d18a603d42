#include "control/evaluation_budget.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::problems {

namespace {

void CheckBudget(int budget) {
  if (budget < 1) {
    std::ostringstream msg;
    msg << "evaluations = " << budget << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
}

}  // namespace

EvaluationBudget::EvaluationBudget(const solvers::RolloutFunction* function, int budget, int steps_per_rollout,
                                   FILE* log)
    : budget_(budget), steps_(steps_per_rollout), log_(log) {
  DIFFPD_CHECK(function != nullptr, "EvaluationBudget needs a rollout function");
  CheckBudget(budget);
  statistics_ = [function] { return function->statistics(); };
  seen_forward_ = function->statistics().forward_seconds;
  seen_backward_ = function->statistics().backward_seconds;
}

EvaluationBudget::EvaluationBudget(const solvers::RolloutSet* set, int budget, int steps_per_rollout, FILE* log)
    : budget_(budget), steps_(steps_per_rollout), log_(log) {
  DIFFPD_CHECK(set != nullptr, "EvaluationBudget needs a rollout set");
  CheckBudget(budget);
  statistics_ = [set] { return set->statistics(); };
  const solvers::RolloutStatistics stats = set->statistics();
  seen_forward_ = stats.forward_seconds;
  seen_backward_ = stats.backward_seconds;
}

bool EvaluationBudget::Admit(const Eigen::Ref<const VectorXd>& p) {
  if (latest_.size() == p.size() && latest_ == p) return true;
  if (used_ >= budget_) {
    exhausted_ = true;
    return false;
  }
  return true;
}

void EvaluationBudget::Record(const Eigen::Ref<const VectorXd>& p, bool ok, double loss, const VectorXd* gradient) {
  const solvers::RolloutStatistics stats = statistics_();
  const double forward = stats.forward_seconds - seen_forward_;
  const double backward = stats.backward_seconds - seen_backward_;
  seen_forward_ = stats.forward_seconds;
  seen_backward_ = stats.backward_seconds;
  const bool is_new = !(latest_.size() == p.size() && latest_ == p);
  if (is_new) {
    Finish();
    latest_ = p;
    ++used_;
    latest_recorded_ = ok;
    if (!ok) {
      ++failed_;
      return;
    }
    TrainingEvaluation row;
    row.evaluation = static_cast<int>(history_.size());
    row.simulated_steps = static_cast<long>(used_ - 1) * steps_;
    row.reward = -loss;
    row.forward_seconds = forward;
    history_.push_back(row);
  } else if (!latest_recorded_) {
    return;
  }
  TrainingEvaluation& row = history_.back();
  if (!is_new) row.forward_seconds += forward;
  if (ok && gradient) {
    row.backward_seconds += backward;
    row.gradient_norm = gradient->norm();
  }
  if (ok && gradient) {
    Print(row);
    pending_print_ = false;
  } else if (is_new) {
    pending_print_ = true;
  }
}

void EvaluationBudget::Finish() {
  if (pending_print_ && !history_.empty()) Print(history_.back());
  pending_print_ = false;
}

void EvaluationBudget::Print(const TrainingEvaluation& row) const {
  if (!log_) return;
  std::fprintf(log_, "%5d %9ld %14.6f %10.3f %10.3f %12.4e\n", row.evaluation, row.simulated_steps, row.reward,
               row.forward_seconds, row.backward_seconds, row.gradient_norm);
  std::fflush(log_);
}

}  // namespace diffpd::problems
