#include "diffpd/solvers/ipopt/rollout_set_nlp.h"

#include <algorithm>
#include <cmath>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

constexpr double kIpoptInfinity = 1e20;  // beyond Ipopt's default nlp_{lower,upper}_bound_inf (1e19)

}  // namespace

RolloutSetNlp::RolloutSetNlp(RolloutSet* set) : set_(set) {
  if (set == nullptr) throw InvalidInputError("RolloutSetNlp: the rollout set is null");
}

bool RolloutSetNlp::Objective(const VectorXd& p, double* f) { return set_->Value(p, f) && std::isfinite(*f); }

bool RolloutSetNlp::ObjectiveGradient(const VectorXd& p, VectorXd* gradient) {
  return set_->Gradient(p, gradient, nullptr) && gradient->allFinite();
}

double RolloutSetNlp::BoundViolation(const VectorXd& p) const {
  const VectorXd lower = set_->lower_bounds(), upper = set_->upper_bounds();
  double v = 0;
  for (Eigen::Index i = 0; i < p.size(); ++i) v = std::max({v, lower(i) - p(i), p(i) - upper(i)});
  return v;
}

bool RolloutSetNlp::get_nlp_info(Ipopt::Index& n, Ipopt::Index& m, Ipopt::Index& nnz_jac_g, Ipopt::Index& nnz_h_lag,
                                 IndexStyleEnum& index_style) {
  n = num_variables();
  m = 0;
  nnz_jac_g = 0;
  nnz_h_lag = 0;
  index_style = C_STYLE;
  return true;
}

bool RolloutSetNlp::get_bounds_info(Ipopt::Index n, Ipopt::Number* x_l, Ipopt::Number* x_u, Ipopt::Index,
                                    Ipopt::Number*, Ipopt::Number*) {
  const VectorXd lower = set_->lower_bounds(), upper = set_->upper_bounds();
  for (Ipopt::Index i = 0; i < n; ++i) {
    x_l[i] = std::isfinite(lower(i)) ? lower(i) : -kIpoptInfinity;
    x_u[i] = std::isfinite(upper(i)) ? upper(i) : kIpoptInfinity;
  }
  return true;
}

bool RolloutSetNlp::get_starting_point(Ipopt::Index n, bool init_x, Ipopt::Number* x, bool init_z, Ipopt::Number*,
                                       Ipopt::Number*, Ipopt::Index, bool init_lambda, Ipopt::Number*) {
  if (init_z || init_lambda) return false;  // no multipliers to offer
  if (init_x) Eigen::Map<VectorXd>(x, n) = starting_point();
  return true;
}

bool RolloutSetNlp::eval_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number& obj_value) {
  return Objective(Eigen::Map<const VectorXd>(x, n), &obj_value);
}

bool RolloutSetNlp::eval_grad_f(Ipopt::Index n, const Ipopt::Number* x, bool, Ipopt::Number* grad_f) {
  VectorXd g;
  if (!ObjectiveGradient(Eigen::Map<const VectorXd>(x, n), &g)) return false;
  Eigen::Map<VectorXd>(grad_f, n) = g;
  return true;
}

bool RolloutSetNlp::eval_g(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Number*) { return true; }

bool RolloutSetNlp::eval_jac_g(Ipopt::Index, const Ipopt::Number*, bool, Ipopt::Index, Ipopt::Index, Ipopt::Index*,
                               Ipopt::Index*, Ipopt::Number*) {
  return true;
}

bool RolloutSetNlp::intermediate_callback(Ipopt::AlgorithmMode, Ipopt::Index, Ipopt::Number obj_value, Ipopt::Number,
                                          Ipopt::Number, Ipopt::Number, Ipopt::Number, Ipopt::Number, Ipopt::Number,
                                          Ipopt::Number, Ipopt::Index, const Ipopt::IpoptData*,
                                          Ipopt::IpoptCalculatedQuantities*) {
  objective_history_.push_back(obj_value);
  return true;
}

void RolloutSetNlp::finalize_solution(Ipopt::SolverReturn, Ipopt::Index n, const Ipopt::Number* x, const Ipopt::Number*,
                                      const Ipopt::Number*, Ipopt::Index, const Ipopt::Number*, const Ipopt::Number*,
                                      Ipopt::Number, const Ipopt::IpoptData*, Ipopt::IpoptCalculatedQuantities*) {
  has_solution_ = x != nullptr;
  if (has_solution_) solution_ = Eigen::Map<const VectorXd>(x, n);
}

}  // namespace diffpd::solvers
