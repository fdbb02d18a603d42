#include "diffpd/solvers/core/external_force_block.h"

#include <algorithm>
#include <sstream>

#include "diffpd/error.h"
#include "node_checks.h"

namespace diffpd::solvers {
namespace {

// Sum of the 3-vectors of `v` (3n) at `nodes`, projected on `direction`.
double SumAlong(const VectorXd& v, const std::vector<int>& nodes, const Vec3& direction) {
  double sum = 0;
  for (int node : nodes) sum += direction.dot(v.segment<3>(3 * node));
  return sum;
}

}  // namespace

ExternalForceBlock::ExternalForceBlock(std::vector<Channel> channels)
    : ParameterBlock(0), channels_(std::move(channels)) {
  if (channels_.empty()) throw InvalidInputError("external_force: no channel");
  offsets_.push_back(0);
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "external_force channel " + std::to_string(c);
    internal::CheckNodes(channels_[c].nodes, what);
    if (!channels_[c].signal) throw InvalidInputError(what + ": no signal");
    if (!channels_[c].direction.allFinite()) throw InvalidInputError(what + ": the direction is not finite");
    if (channels_[c].signal->num_steps() != channels_[0].signal->num_steps()) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, channel 0's has "
          << channels_[0].signal->num_steps();
      throw InvalidInputError(msg.str());
    }
    const int p = channels_[c].signal->num_coefficients();
    Append(p);
    offsets_.push_back(offsets_.back() + p);
  }
}

int ExternalForceBlock::ChannelOf(int j) const {
  int c = 0;
  while (offsets_[c + 1] <= j) ++c;
  return c;
}

void ExternalForceBlock::CheckFits(const Scene& scene, int num_steps) const {
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "external_force channel " + std::to_string(c);
    internal::CheckNodesFit(channels_[c].nodes, scene.mesh.num_vertices(), what);
    if (channels_[c].signal->num_steps() != num_steps) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, the rollout has " << num_steps;
      throw InvalidInputError(msg.str());
    }
  }
}

void ExternalForceBlock::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  const Eigen::Index n = setup->initial.x.size();
  VectorXd s;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], offsets_[c + 1] - offsets_[c]), &s, nullptr);
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      VectorXd& f = setup->inputs[k].external_force;
      if (f.size() == 0) f = VectorXd::Zero(n);
      for (int node : ch.nodes) f.segment<3>(3 * node) += s(k) * ch.direction;
    }
  }
}

void ExternalForceBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                  Eigen::Ref<VectorXd> out) const {
  VectorXd ds;
  MatrixXd jacobian;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    const int p = offsets_[c + 1] - offsets_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], p), nullptr, &jacobian);
    ds = VectorXd::Zero(ch.signal->num_steps());
    const Eigen::Index known = std::min<Eigen::Index>(ds.size(), grad.external_force.size());
    for (Eigen::Index k = 0; k < known; ++k)
      if (grad.external_force[k].size()) ds(k) = SumAlong(grad.external_force[k], ch.nodes, ch.direction);
    out.segment(offsets_[c], p) = jacobian.transpose() * ds;
  }
}

int ExternalForceBlock::FirstAffectedState(int j) const {
  const int c = ChannelOf(j);
  return channels_[c].signal->FirstStep(j - offsets_[c]) + 1;
}

void ExternalForceBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                                     InputDirection* direction) const {
  const int c = ChannelOf(j);
  const Channel& ch = channels_[c];
  MatrixXd jacobian;
  ch.signal->Evaluate(values.segment(offsets_[c], offsets_[c + 1] - offsets_[c]), nullptr, &jacobian);
  const Eigen::Index n = direction->x0.size();
  for (Eigen::Index k = 0; k < jacobian.rows(); ++k) {
    const double ds = jacobian(k, j - offsets_[c]);
    if (ds == 0) continue;
    VectorXd& f = direction->external_force[k];
    if (f.size() == 0) f = VectorXd::Zero(n);
    for (int node : ch.nodes) f.segment<3>(3 * node) += ds * ch.direction;
  }
}

}  // namespace diffpd::solvers
