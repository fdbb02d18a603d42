#include "control/swim_loss.h"

#include "diffpd/error.h"

namespace diffpd::problems {

double SwimLoss::Evaluate(const Rollout& rollout, LossGradient* grad) const {
  DIFFPD_CHECK(!nodes.empty(), "SwimLoss: no nodes");
  const int steps = rollout.num_steps();
  const int n = static_cast<int>(rollout.states[0].v.size());
  if (grad) *grad = LossGradient(steps);
  const double share = 1.0 / static_cast<double>(nodes.size());
  double loss = 0;
  for (int k = 1; k <= steps; ++k) {
    const VectorXd& v = rollout.states[k].v;
    Vec3 mean = Vec3::Zero();
    for (const int i : nodes) mean += v.segment<3>(3 * i);
    mean *= share;
    const double forward = direction.dot(mean);
    const Vec3 side = mean - forward * direction;
    loss += -forward + side_weight * side.squaredNorm();
    if (!grad) continue;
    // dL/dvbar = -d + 2 w (I - d d^T) side = -d + 2 w side.
    const Vec3 g_mean = -direction + 2 * side_weight * side;
    VectorXd& dv = grad->dv[k];
    dv = VectorXd::Zero(n);
    for (const int i : nodes) dv.segment<3>(3 * i) += share * g_mean;
  }
  return loss;
}

void SwimLossFunction::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  LossGradient own;
  loss_.Evaluate(rollout, &own);
  const int steps = rollout.num_steps();
  if (static_cast<int>(loss->dx.size()) < steps + 1) loss->dx.resize(steps + 1);
  if (static_cast<int>(loss->dv.size()) < steps + 1) loss->dv.resize(steps + 1);
  for (int k = 1; k <= steps; ++k) {
    if (!own.dv[k].size()) continue;
    VectorXd& dv = loss->dv[k];
    if (!dv.size()) dv = VectorXd::Zero(own.dv[k].size());
    dv += weight * own.dv[k];
  }
}

}  // namespace diffpd::problems
