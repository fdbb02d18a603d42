// Muscle activations (muscle.h) driven by control signals
// (control_signal.h) as parameters: channel c sets the activation of
// Scene::muscles[muscle] to s_k during step k (1 = rest, < 1 contracts).
// Muscles without a channel keep the setup's activation (RolloutFunction
// fills a base without activations with 1). The parameters are the
// channels' coefficients, channel after channel; starting values: a constant
// signal of 1 (rest).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "diffpd/solvers/core/control_signal.h"
#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::solvers {

class ActivationBlock : public ParameterBlock {
 public:
  struct Channel {
    int muscle = 0;
    std::unique_ptr<ControlSignal> signal;
  };
  // Throws InvalidInputError if there is no channel, a channel has a
  // negative muscle or no signal, two channels drive the same muscle
  // ("activation channel 1: muscle 0 is already driven by channel 0"), or
  // the signals have different numbers of steps.
  explicit ActivationBlock(std::vector<Channel> channels);
  std::string name() const override { return "activation"; }
  int num_channels() const { return static_cast<int>(channels_.size()); }
  int channel_offset(int c) const { return offsets_[c]; }
  const Channel& channel(int c) const { return channels_[c]; }
  // Throws for a muscle out of range ("activation channel 0: muscle 4 is out
  // of range: the scene has 4 muscles") or a signal of another length.
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override;
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                   InputDirection* direction) const override;

 private:
  int ChannelOf(int j) const;
  std::vector<Channel> channels_;
  std::vector<int> offsets_;  // num_channels + 1
};

}  // namespace diffpd::solvers
