// The original swimmers' loss (DiffPD Sec. 7.4), summed over the steps
// k = 1..K of a rollout:
//   L = sum_k [ -d . vbar_k + side_weight |vbar_k - (d . vbar_k) d|^2 ],
// vbar_k the mean velocity of `nodes` after step k (m/s), d the unit swim
// direction; the reward is -L. SwimLossFunction is the same loss as a
// trajectory function of the rollout core (solvers/core).
#pragma once

#include <string>
#include <vector>

#include "diffpd/rollout.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "diffpd/types.h"

namespace diffpd::problems {

struct SwimLoss {
  std::vector<int> nodes;
  Vec3 direction = Vec3::UnitZ();
  double side_weight = 1.0;
  // L of a rollout; fills grad->dv (and sizes *grad) when not nullptr.
  double Evaluate(const Rollout& rollout, LossGradient* grad) const;
};

class SwimLossFunction : public solvers::TrajectoryFunction {
 public:
  explicit SwimLossFunction(SwimLoss loss) : loss_(std::move(loss)) {}
  std::string name() const override { return "swim_loss"; }
  int LastState(int num_steps) const override { return num_steps; }
  double Value(const Rollout& rollout) const override { return loss_.Evaluate(rollout, nullptr); }
  void AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const override;

 private:
  SwimLoss loss_;
};

}  // namespace diffpd::problems
