#include "diffpd/solvers/ceres/rollout_set_loss_function.h"

#include "diffpd/error.h"

namespace diffpd::solvers {

RolloutSetLossFunction::RolloutSetLossFunction(RolloutSet* set) : set_(set) {
  DIFFPD_CHECK(set_ != nullptr, "RolloutSetLossFunction needs a rollout set");
}

bool RolloutSetLossFunction::Evaluate(const double* parameters, double* cost, double* gradient) const {
  const Eigen::Map<const VectorXd> p(parameters, set_->num_parameters());
  if (gradient) {
    VectorXd g;
    if (!set_->Gradient(p, &g, cost)) return false;
    Eigen::Map<VectorXd>(gradient, g.size()) = g;
    return true;
  }
  return set_->Value(p, cost);
}

}  // namespace diffpd::solvers
