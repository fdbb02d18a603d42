// The least-squares loss of a vector functional as a scalar function:
//   L = 1/2 |r|^2 = 1/2 sum_i r_i^2,  dL/d(states) = sum_i r_i dr_i/d(states).
// E.g. LeastSquaresLoss(std::make_unique<MarkerResiduals>(...)) is the
// marker-fitting loss whose gradient is one adjoint.
#pragma once

#include <memory>
#include <string>

#include "diffpd/solvers/core/trajectory_function.h"

namespace diffpd::solvers {

class LeastSquaresLoss : public TrajectoryFunction {
 public:
  // Takes ownership of `residuals`. Throws InvalidInputError if it is null.
  explicit LeastSquaresLoss(std::unique_ptr<TrajectoryFunctional> residuals);
  std::string name() const override { return "least_squares(" + residuals_->name() + ")"; }
  int LastState(int num_steps) const override;
  double Value(const Rollout& rollout) const override;
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;
  const TrajectoryFunctional& residuals() const { return *residuals_; }

 private:
  std::unique_ptr<TrajectoryFunctional> residuals_;
};

}  // namespace diffpd::solvers
