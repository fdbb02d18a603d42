#include "diffpd/solvers/core/rollout_set.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {

void CheckRolloutTerm(const RolloutTerm& term) {
  if (!term.function) throw InvalidInputError("rollout term: no rollout function");
  if (term.rows.empty()) throw InvalidInputError("rollout term: no row");
  const int num_rows = term.function->num_rows();
  for (int r : term.rows)
    if (r < 0 || r >= num_rows) {
      std::ostringstream msg;
      msg << "rollout term: row " << r << " is out of range [0, " << num_rows << ")";
      throw InvalidInputError(msg.str());
    }
}

bool EvaluateRolloutTerm(RolloutTerm* term, const Eigen::Ref<const VectorXd>& p, VectorXd* values, MatrixXd* jacobian,
                         std::string* error) {
  if (term->function->Evaluate(p, term->rows, values, jacobian)) return true;
  *error = term->function->statistics().last_error;
  return false;
}

bool RolloutTermGradient(RolloutTerm* term, TermObjective objective, const Eigen::Ref<const VectorXd>& p,
                         VectorXd* gradient, double* value, std::string* error) {
  RolloutFunction& f = *term->function;
  VectorXd weights = VectorXd::Zero(f.num_rows());
  if (objective == TermObjective::kLeastSquares) {
    // dL/dp = sum_r v_r dv_r/dp: the rows weighted by their values.
    VectorXd v;
    if (!f.Evaluate(p, term->rows, &v, nullptr)) {
      *error = f.statistics().last_error;
      return false;
    }
    for (size_t i = 0; i < term->rows.size(); ++i) weights(term->rows[i]) = v(i);
  } else {
    for (int r : term->rows) weights(r) = 1.0;
  }
  double weighted = 0;
  if (!f.Gradient(p, weights, gradient, &weighted)) {
    *error = f.statistics().last_error;
    return false;
  }
  if (value) *value = objective == TermObjective::kLeastSquares ? 0.5 * weighted : weighted;
  return true;
}

bool RolloutSet::Value(const Eigen::Ref<const VectorXd>& p, double* value) {
  VectorXd v;
  if (!Evaluate(p, &v, nullptr)) return false;
  *value = objective() == TermObjective::kLeastSquares ? 0.5 * v.squaredNorm() : v.sum();
  return true;
}

LocalRolloutSet::LocalRolloutSet(std::vector<RolloutTerm> terms, TermObjective objective)
    : terms_(std::move(terms)), objective_(objective) {
  if (terms_.empty()) throw InvalidInputError("LocalRolloutSet: no term");
  for (size_t t = 0; t < terms_.size(); ++t) {
    CheckRolloutTerm(terms_[t]);
    if (terms_[t].function->num_parameters() != terms_[0].function->num_parameters()) {
      std::ostringstream msg;
      msg << "LocalRolloutSet: term " << t << " has " << terms_[t].function->num_parameters()
          << " parameters, term 0 has " << terms_[0].function->num_parameters();
      throw InvalidInputError(msg.str());
    }
    num_rows_ += static_cast<int>(terms_[t].rows.size());
  }
}

bool LocalRolloutSet::Evaluate(const Eigen::Ref<const VectorXd>& p, VectorXd* values, MatrixXd* jacobian) {
  values->resize(num_rows_);
  if (jacobian) jacobian->resize(num_rows_, num_parameters());
  int row = 0;
  for (size_t t = 0; t < terms_.size(); ++t) {
    VectorXd v;
    MatrixXd j;
    std::string error;
    if (!EvaluateRolloutTerm(&terms_[t], p, &v, jacobian ? &j : nullptr, &error)) {
      last_error_ = "term " + std::to_string(t) + ": " + error;
      return false;
    }
    values->segment(row, v.size()) = v;
    if (jacobian) jacobian->middleRows(row, v.size()) = j;
    row += static_cast<int>(v.size());
  }
  return true;
}

bool LocalRolloutSet::Gradient(const Eigen::Ref<const VectorXd>& p, VectorXd* gradient, double* value) {
  *gradient = VectorXd::Zero(num_parameters());
  double sum = 0;
  for (size_t t = 0; t < terms_.size(); ++t) {
    VectorXd g;
    double v = 0;
    std::string error;
    if (!RolloutTermGradient(&terms_[t], objective_, p, &g, &v, &error)) {
      last_error_ = "term " + std::to_string(t) + ": " + error;
      return false;
    }
    *gradient += g;
    sum += v;
  }
  if (value) *value = sum;
  return true;
}

RolloutStatistics LocalRolloutSet::statistics() const {
  RolloutStatistics total;
  for (const RolloutTerm& t : terms_) total = total + t.function->statistics();
  return total;
}

RolloutStatistics operator+(const RolloutStatistics& a, const RolloutStatistics& b) {
  RolloutStatistics s;
  s.rollouts = a.rollouts + b.rollouts;
  s.failed_rollouts = a.failed_rollouts + b.failed_rollouts;
  s.jacobians = a.jacobians + b.jacobians;
  s.gradients = a.gradients + b.gradients;
  s.adjoint_passes = a.adjoint_passes + b.adjoint_passes;
  s.tangent_passes = a.tangent_passes + b.tangent_passes;
  s.failures = a.failures + b.failures;
  s.forward_seconds = a.forward_seconds + b.forward_seconds;
  s.backward_seconds = a.backward_seconds + b.backward_seconds;
  s.last_error = b.last_error.empty() ? a.last_error : b.last_error;
  return s;
}

}  // namespace diffpd::solvers
