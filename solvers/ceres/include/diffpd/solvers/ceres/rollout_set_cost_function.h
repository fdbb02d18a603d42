// The rows of a RolloutSet (diffpd/solvers/core/rollout_set.h) as one Ceres
// residual block over one parameter block of the set's N parameters:
//
//   LocalRolloutSet set(std::move(terms), TermObjective::kLeastSquares);  // or a DistributedRolloutSet
//   std::vector<double> p = ...;                                          // N values
//   problem.AddResidualBlock(new RolloutSetCostFunction(&set), nullptr, p.data());
//
// One block, so that each Ceres evaluation is one evaluation of every term
// (one broadcast of p and one gather when the set is distributed).
#pragma once

#include <ceres/cost_function.h>

#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::solvers {

class RolloutSetCostFunction : public ceres::CostFunction {
 public:
  // Does not take ownership of `set`, which must outlive this object.
  explicit RolloutSetCostFunction(RolloutSet* set);

  // Returns false (never throws) when a term fails (the reason in the
  // set's last_error()). The Jacobian is row-major (residual-major).
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

 private:
  RolloutSet* set_;
};

}  // namespace diffpd::solvers
