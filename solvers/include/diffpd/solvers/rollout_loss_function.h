// A scalar loss of a rollout as a ceres::FirstOrderFunction, for
// ceres::GradientProblem (line-search methods: L-BFGS, BFGS, CG).
//
//   RolloutLossFunction f(&model);          // 1/2 |r|^2 of the marker residuals
//   ceres::GradientProblem problem(&f);     // does not take ownership of f here:
//   // use new RolloutLossFunction(...) if the problem should own it
//   std::vector<double> x = ...;            // the model's blocks, concatenated
//   ceres::Solve(options, problem, x.data(), &summary);
//
// The parameter vector is the concatenation of the model's parameter blocks
// (material block, then input block). The gradient comes from one adjoint
// (Simulator::Backward) whatever the model's JacobianMode.
// Ceres' line searches try a first step as long as the (tangent-space)
// gradient: scale the loss to O(1) or less (e.g. residuals in metres, weights
// near 1) and use a CoordinateManifold so that the tangent coordinates are
// comparable (log E, logit nu).
#pragma once

#include <ceres/first_order_function.h>

#include "diffpd/solvers/calibration_model.h"

namespace diffpd::solvers {

class RolloutLossFunction : public ceres::FirstOrderFunction {
 public:
  // `loss` empty: the least-squares marker loss 1/2 sum r^2. Does not take
  // ownership of `model`, which must outlive this object.
  explicit RolloutLossFunction(CalibrationModel* model, TrajectoryLoss loss = {});

  // Returns false (never throws) when the rollout or the gradient fails.
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override;
  int NumParameters() const override { return num_parameters_; }

 private:
  CalibrationModel* model_;
  TrajectoryLoss loss_;
  int num_parameters_ = 0;
};

}  // namespace diffpd::solvers
