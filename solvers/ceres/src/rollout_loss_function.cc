#include "diffpd/solvers/ceres/rollout_loss_function.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {

RolloutLossFunction::RolloutLossFunction(RolloutFunction* function, int functional) : function_(function) {
  DIFFPD_CHECK(function_ != nullptr, "RolloutLossFunction needs a rollout function");
  std::ostringstream msg;
  msg << "RolloutLossFunction: functional " << functional;
  if (functional < 0 || functional >= function_->num_functionals()) {
    msg << " is out of range [0, " << function_->num_functionals() << ")";
    throw InvalidInputError(msg.str());
  }
  const TrajectoryFunctional& f = function_->functional(functional);
  if (f.num_values() != 1) {
    msg << " ('" << f.name() << "') has " << f.num_values() << " values, expected 1";
    throw InvalidInputError(msg.str());
  }
  row_ = function_->functional_row(functional);
}

bool RolloutLossFunction::Evaluate(const double* parameters, double* cost, double* gradient) const {
  const Eigen::Map<const VectorXd> p(parameters, function_->num_parameters());
  if (!gradient) {
    VectorXd value;
    if (!function_->Evaluate(p, {row_}, &value, nullptr)) return false;
    *cost = value(0);
    return true;
  }
  VectorXd weights = VectorXd::Zero(function_->num_rows()), g;
  weights(row_) = 1;
  if (!function_->Gradient(p, weights, &g, cost)) return false;
  Eigen::Map<VectorXd>(gradient, g.size()) = g;
  return true;
}

}  // namespace diffpd::solvers
