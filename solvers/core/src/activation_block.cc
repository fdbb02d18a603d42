#include "diffpd/solvers/core/activation_block.h"

#include <algorithm>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {

ActivationBlock::ActivationBlock(std::vector<Channel> channels) : ParameterBlock(0), channels_(std::move(channels)) {
  if (channels_.empty()) throw InvalidInputError("activation: no channel");
  offsets_.push_back(0);
  VectorXd initial;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "activation channel " + std::to_string(c);
    if (channels_[c].muscle < 0) {
      std::ostringstream msg;
      msg << what << ": muscle " << channels_[c].muscle << " is invalid: must be >= 0";
      throw InvalidInputError(msg.str());
    }
    for (size_t d = 0; d < c; ++d)
      if (channels_[d].muscle == channels_[c].muscle) {
        std::ostringstream msg;
        msg << what << ": muscle " << channels_[c].muscle << " is already driven by channel " << d;
        throw InvalidInputError(msg.str());
      }
    if (!channels_[c].signal) throw InvalidInputError(what + ": no signal");
    if (channels_[c].signal->num_steps() != channels_[0].signal->num_steps()) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, channel 0's has "
          << channels_[0].signal->num_steps();
      throw InvalidInputError(msg.str());
    }
    const int p = channels_[c].signal->num_coefficients();
    Append(p);
    offsets_.push_back(offsets_.back() + p);
    initial.conservativeResize(offsets_.back());
    initial.tail(p) = channels_[c].signal->ConstantCoefficients(1.0);
  }
  SetInitial(initial);
}

int ActivationBlock::ChannelOf(int j) const {
  int c = 0;
  while (offsets_[c + 1] <= j) ++c;
  return c;
}

void ActivationBlock::CheckFits(const Scene& scene, int num_steps) const {
  for (size_t c = 0; c < channels_.size(); ++c) {
    const std::string what = "activation channel " + std::to_string(c);
    if (channels_[c].muscle >= static_cast<int>(scene.muscles.size())) {
      std::ostringstream msg;
      msg << what << ": muscle " << channels_[c].muscle << " is out of range: the scene has " << scene.muscles.size()
          << " muscles";
      throw InvalidInputError(msg.str());
    }
    if (channels_[c].signal->num_steps() != num_steps) {
      std::ostringstream msg;
      msg << what << ": its signal has " << channels_[c].signal->num_steps() << " steps, the rollout has " << num_steps;
      throw InvalidInputError(msg.str());
    }
  }
}

void ActivationBlock::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  VectorXd s;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], offsets_[c + 1] - offsets_[c]), &s, nullptr);
    for (Eigen::Index k = 0; k < s.size(); ++k) {
      VectorXd& a = setup->inputs[k].activation;
      if (a.size() <= ch.muscle) {
        const Eigen::Index old = a.size();
        a.conservativeResize(ch.muscle + 1);
        a.tail(a.size() - old).setOnes();
      }
      a(ch.muscle) = s(k);
    }
  }
}

void ActivationBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                               Eigen::Ref<VectorXd> out) const {
  VectorXd ds;
  MatrixXd jacobian;
  for (size_t c = 0; c < channels_.size(); ++c) {
    const Channel& ch = channels_[c];
    const int p = offsets_[c + 1] - offsets_[c];
    ch.signal->Evaluate(values.segment(offsets_[c], p), nullptr, &jacobian);
    ds = VectorXd::Zero(ch.signal->num_steps());
    const Eigen::Index known = std::min<Eigen::Index>(ds.size(), grad.activation.size());
    for (Eigen::Index k = 0; k < known; ++k)
      if (grad.activation[k].size() > ch.muscle) ds(k) = grad.activation[k](ch.muscle);
    out.segment(offsets_[c], p) = jacobian.transpose() * ds;
  }
}

int ActivationBlock::FirstAffectedState(int j) const {
  const int c = ChannelOf(j);
  return channels_[c].signal->FirstStep(j - offsets_[c]) + 1;
}

void ActivationBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                                  InputDirection* direction) const {
  const int c = ChannelOf(j);
  const Channel& ch = channels_[c];
  MatrixXd jacobian;
  ch.signal->Evaluate(values.segment(offsets_[c], offsets_[c + 1] - offsets_[c]), nullptr, &jacobian);
  for (Eigen::Index k = 0; k < jacobian.rows(); ++k) {
    const double ds = jacobian(k, j - offsets_[c]);
    if (ds == 0) continue;
    VectorXd& a = direction->activation[k];
    if (a.size() == 0) a = VectorXd::Zero(setup.inputs[k].activation.size());
    a(ch.muscle) += ds;
  }
}

}  // namespace diffpd::solvers
