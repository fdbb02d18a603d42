// External forces driven by control signals (control_signal.h) as
// parameters. Channel c applies the force
//   f_k = s_k * direction  (N per node; direction dimensionless)
// to each of its nodes during step k, s = signal(coefficients of channel c).
// The parameters are the channels' coefficients, channel after channel;
// starting values 0. Forces add to the setup's external forces.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "diffpd/solvers/core/control_signal.h"
#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::solvers {

class ExternalForceBlock : public ParameterBlock {
 public:
  struct Channel {
    std::vector<int> nodes;
    Vec3 direction = Vec3::UnitX();
    std::unique_ptr<ControlSignal> signal;
  };
  // Throws InvalidInputError if there is no channel, a channel has no node,
  // a negative node, no signal, a non-finite direction, or the signals have
  // different numbers of steps ("external_force channel 1: its signal has 4
  // steps, channel 0's has 5").
  explicit ExternalForceBlock(std::vector<Channel> channels);
  std::string name() const override { return "external_force"; }
  int num_channels() const { return static_cast<int>(channels_.size()); }
  // First parameter of channel c.
  int channel_offset(int c) const { return offsets_[c]; }
  const Channel& channel(int c) const { return channels_[c]; }
  // Throws for a node out of range or a signal whose length is not the
  // rollout's ("external_force channel 0: its signal has 4 steps, the rollout has 5").
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
