// Vector-valued functions of a recorded trajectory,
//   r(x_0..x_K, v_0..v_K) in R^m,
// with their derivatives w.r.t. the states: the rows a RolloutFunction
// (rollout_function.h) evaluates and differentiates w.r.t. its parameters.
// Scalar functions derive from TrajectoryFunction (trajectory_function.h);
// captured-marker residuals are MarkerResiduals (marker_residuals.h).
#pragma once

#include <string>

#include "diffpd/rollout.h"
#include "diffpd/tangent_rollout.h"
#include "diffpd/types.h"

namespace diffpd::solvers {

class TrajectoryFunctional {
 public:
  virtual ~TrajectoryFunctional() = default;
  // Names the functional in messages.
  virtual std::string name() const = 0;
  // m >= 1.
  virtual int num_values() const = 0;
  // The latest state index (0..K) that value i reads in a rollout of K steps.
  virtual int LastStateOf(int i, int num_steps) const = 0;
  // values (m) on `rollout`, which holds at least the states the values read.
  // May throw InvalidInputError or SolverError.
  virtual void Evaluate(const Rollout& rollout, Eigen::Ref<VectorXd> values) const = 0;
  // Adds sum_i weights_i d r_i / d x_k and d r_i / d v_k (weights: m) into
  // `loss`, sized for `rollout` (entries allocated as needed; entries the
  // values do not depend on stay empty).
  virtual void AddWeightedGradient(const Rollout& rollout, const Eigen::Ref<const VectorXd>& weights,
                                   LossGradient* loss) const = 0;
  // jacobian (m x P) = sum_k dr/dx_k tangents.dx[k] + dr/dv_k tangents.dv[k]:
  // the derivatives of the values along the P directions of a tangent pass
  // over `rollout`. The default goes through AddWeightedGradient row by row.
  virtual void ApplyTangents(const Rollout& rollout, const TangentRollout& tangents,
                             Eigen::Ref<MatrixXd> jacobian) const;
};

}  // namespace diffpd::solvers
