#include "paper/trajectory_losses.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

// dL/dx_k or dL/dv_k of `loss`, allocated as zero if empty.
VectorXd& Entry(std::vector<VectorXd>* list, size_t k, Eigen::Index size) {
  if (list->size() <= k) list->resize(k + 1);
  if ((*list)[k].size() == 0) (*list)[k] = VectorXd::Zero(size);
  return (*list)[k];
}

}  // namespace

LinearFinalStateLoss::LinearFinalStateLoss(VectorXd position_weights, VectorXd velocity_weights)
    : cx_(std::move(position_weights)), cv_(std::move(velocity_weights)) {
  if (cx_.size() != cv_.size() || !cx_.allFinite() || !cv_.allFinite()) {
    std::ostringstream msg;
    msg << "linear_final_state: weights of sizes " << cx_.size() << " and " << cv_.size()
        << " are invalid: must be of equal size and finite";
    throw InvalidInputError(msg.str());
  }
}

double LinearFinalStateLoss::Value(const Rollout& rollout) const {
  const State& s = rollout.states.back();
  return cx_.dot(s.x) + cv_.dot(s.v);
}

void LinearFinalStateLoss::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  const size_t k = rollout.states.size() - 1;
  Entry(&loss->dx, k, cx_.size()) += weight * cx_;
  Entry(&loss->dv, k, cv_.size()) += weight * cv_;
}

TrajectoryTrackingLoss::TrajectoryTrackingLoss(std::vector<VectorXd> targets) : targets_(std::move(targets)) {
  if (targets_.empty()) throw InvalidInputError("trajectory_tracking: no target state");
  for (size_t k = 1; k < targets_.size(); ++k)
    if (targets_[k].size() != targets_[0].size()) {
      std::ostringstream msg;
      msg << "trajectory_tracking: target " << k << " has " << targets_[k].size() << " entries, target 0 has "
          << targets_[0].size();
      throw InvalidInputError(msg.str());
    }
}

void TrajectoryTrackingLoss::CheckRollout(const Rollout& rollout) const {
  if (rollout.num_steps() != static_cast<int>(targets_.size()) || rollout.states[0].x.size() != targets_[0].size()) {
    std::ostringstream msg;
    msg << "trajectory_tracking: the rollout has " << rollout.num_steps() << " steps of " << rollout.states[0].x.size()
        << " DoFs, the targets " << targets_.size() << " of " << targets_[0].size();
    throw InvalidInputError(msg.str());
  }
}

double TrajectoryTrackingLoss::Value(const Rollout& rollout) const {
  CheckRollout(rollout);
  double sum = 0;
  for (size_t k = 1; k < rollout.states.size(); ++k) sum += 0.5 * (rollout.states[k].x - targets_[k - 1]).squaredNorm();
  return sum;
}

void TrajectoryTrackingLoss::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  CheckRollout(rollout);
  for (size_t k = 1; k < rollout.states.size(); ++k)
    Entry(&loss->dx, k, targets_[0].size()) += weight * (rollout.states[k].x - targets_[k - 1]);
}

}  // namespace diffpd::problems
