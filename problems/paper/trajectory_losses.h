// Losses of the paper's rows that solvers/trajectory_constraint.h does not
// already provide, as TrajectoryFunctions (value and dL/dx_k, dL/dv_k).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "diffpd/solvers/core/trajectory_function.h"

namespace diffpd::problems {

// c_x . x_K + c_v . v_K (the cantilever and rolling-sphere rows' random
// linear loss); c_x, c_v of size 3n.
class LinearFinalStateLoss : public solvers::TrajectoryFunction {
 public:
  // Throws InvalidInputError if the sizes differ or an entry is not finite.
  LinearFinalStateLoss(VectorXd position_weights, VectorXd velocity_weights);
  std::string name() const override { return "linear_final_state"; }
  int LastState(int num_steps) const override { return num_steps; }
  double Value(const Rollout& rollout) const override;
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;

 private:
  VectorXd cx_, cv_;
};

// sum_{k=1..K} (1/2) |x_k - target_k|^2 (m^2): tracking a recorded motion
// over the whole rollout (the plant and bouncing-ball rows). targets[k - 1]
// is the target of state k.
class TrajectoryTrackingLoss : public solvers::TrajectoryFunction {
 public:
  // Throws InvalidInputError if targets is empty or their sizes differ.
  explicit TrajectoryTrackingLoss(std::vector<VectorXd> targets);
  std::string name() const override { return "trajectory_tracking"; }
  int LastState(int num_steps) const override { return num_steps; }
  // Throws InvalidInputError (from Value and AddGradient) if the rollout has
  // another number of steps or state size than the targets.
  double Value(const Rollout& rollout) const override;
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;

 private:
  void CheckRollout(const Rollout& rollout) const;
  std::vector<VectorXd> targets_;
};

}  // namespace diffpd::problems
