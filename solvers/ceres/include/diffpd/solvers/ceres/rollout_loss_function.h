// A scalar functional of a RolloutFunction (rollout_function.h) as a
// ceres::FirstOrderFunction,
// for ceres::GradientProblem (line-search methods: L-BFGS, BFGS, CG); the
// gradient is one adjoint pass whatever the function's DerivativeMode.
//
//   const int loss = f.AddFunctional(std::make_unique<LeastSquaresLoss>(
//       std::make_unique<MarkerResiduals>(motion, mesh, h, num_steps)));   // 1/2 |r|^2
//   ceres::GradientProblem problem(new RolloutLossFunction(&f, loss));  // the problem owns it
//   std::vector<double> x = ...;   // the function's parameters, blocks concatenated
//   ceres::Solve(options, problem, x.data(), &summary);
//
// Ceres' line searches try a first step as long as the (tangent-space)
// gradient: scale the loss to O(1) or less (e.g. residuals in metres, weights
// near 1) and use a CoordinateManifold so that the tangent coordinates are
// comparable (log E, logit nu).
#pragma once

#include <ceres/first_order_function.h>

#include "diffpd/solvers/core/rollout_function.h"

namespace diffpd::solvers {

class RolloutLossFunction : public ceres::FirstOrderFunction {
 public:
  // The loss is the functional with index `functional` of `function` (e.g. a
  // LeastSquaresLoss); it must have one value. Does not take ownership of
  // `function`, which must outlive this object. Throws InvalidInputError:
  // "RolloutLossFunction: functional 3 is out of range [0, 1)",
  // "RolloutLossFunction: functional 0 ('marker_residuals') has 18 values, expected 1".
  RolloutLossFunction(RolloutFunction* function, int functional);

  // Returns false (never throws) when the rollout or the gradient fails.
  bool Evaluate(const double* parameters, double* cost, double* gradient) const override;
  int NumParameters() const override { return function_->num_parameters(); }

 private:
  RolloutFunction* function_;
  int row_;
};

}  // namespace diffpd::solvers
