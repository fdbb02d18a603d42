// The scalar L(p) of a RolloutSet (diffpd/solvers/core/rollout_set.h) as a
// ceres::FirstOrderFunction, for ceres::GradientProblem (L-BFGS and the
// other line searches): the gradient is one adjoint pass per term.
#pragma once

#include <ceres/first_order_function.h>

#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::solvers {

class RolloutSetLossFunction : public ceres::FirstOrderFunction {
 public:
  // Does not take ownership of `set`, which must outlive this object.
  explicit RolloutSetLossFunction(RolloutSet* set);

  // Returns false (never throws) when a term fails.
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override;
  int NumParameters() const override { return set_->num_parameters(); }

 private:
  RolloutSet* set_;
};

}  // namespace diffpd::solvers
