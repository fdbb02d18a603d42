// Blocks of decision variables for trajectory optimisation: each block owns
// a slice of the optimiser's vector, writes it into what a rollout is made
// from (RolloutSetup), and pulls a rollout gradient back onto its slice.
//
//   auto v0 = std::make_unique<InitialStateVariables>(InitialStateVariables::kVelocity, all_nodes);
//   v0->SetBounds(-2.0, 2.0);                         // m/s
//   nlp->AddVariables(std::move(v0));                  // see rollout_nlp.h
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "diffpd/material.h"
#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/tangent_rollout.h"
#include "diffpd/solvers/core/control_signal.h"
#include "diffpd/solvers/core/rollout_setup.h"
#include "diffpd/types.h"

namespace diffpd::solvers {

class ControlVariables {
 public:
  virtual ~ControlVariables() = default;
  virtual std::string name() const = 0;
  int size() const { return static_cast<int>(initial_.size()); }

  // Bounds (units of the block's variables; +-infinity: none) and starting
  // values. Defaults: unbounded, the starting values the block chose.
  // Throw InvalidInputError on a size mismatch, NaN, or lower > upper.
  void SetBounds(double lower, double upper);
  void SetBounds(int offset, int count, double lower, double upper);
  void SetInitial(const VectorXd& values);
  const VectorXd& lower() const { return lower_; }
  const VectorXd& upper() const { return upper_; }
  const VectorXd& initial() const { return initial_; }

  // Throws InvalidInputError if the block does not fit a rollout of `scene`
  // with `num_steps` steps (node or muscle out of range, signal of another
  // length).
  virtual void CheckFits(const Scene& scene, int num_steps) const = 0;
  // Writes the effect of `values` (size()) into `setup`.
  virtual void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const = 0;
  // out (size()) = dL/d(values), given the gradient of L w.r.t. the rollout
  // inputs at the setup made from `values`. grad.external_force may hold
  // fewer than K steps (a rollout truncated after the loss's last state):
  // the missing steps have zero gradient.
  virtual void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                        Eigen::Ref<VectorXd> out) const = 0;
  // The earliest state index k (0..K) that variable j can influence: 0 for
  // the initial state, i + 1 for an input of step i, K + 1 for none.
  virtual int FirstAffectedState(int j) const = 0;
  // Forward mode: adds d(setup)/d(values_j) into `direction` (the
  // simulator's InputDirection, per-step lists sized for K steps) and
  // returns true; returns false if the block drives an input that forward
  // mode cannot represent (muscle activations), and then the NLP uses
  // reverse mode.
  virtual bool AddDirection(const Eigen::Ref<const VectorXd>& values, int j, int num_steps,
                            InputDirection* direction) const {
    return false;
  }

 protected:
  explicit ControlVariables(int size);
  void Append(int count);  // adds `count` unbounded variables starting at 0

 private:
  VectorXd lower_, upper_, initial_;
};

// Initial positions (m) or velocities (m/s) of a set of nodes, either one
// 3-vector shared by all of them (kShared: 3 variables, a rigid shift of the
// positions or a common velocity) or one 3-vector per node (kPerNode: 3
// variables per node, node-major). The variables are added to the base
// setup's x_0 or v_0; starting values 0.
class InitialStateVariables : public ControlVariables {
 public:
  enum Quantity { kPosition, kVelocity };
  enum Sharing { kShared, kPerNode };
  // Throws InvalidInputError if nodes is empty or has a negative index.
  InitialStateVariables(Quantity quantity, std::vector<int> nodes, Sharing sharing = kShared);
  std::string name() const override;
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 0; }
  bool AddDirection(const Eigen::Ref<const VectorXd>& values, int j, int num_steps,
                    InputDirection* direction) const override;

 private:
  Quantity quantity_;
  std::vector<int> nodes_;
  Sharing sharing_;
};

// External forces driven by control signals. Channel c applies the force
//   f_k = s_k * direction  (N per node; direction dimensionless)
// to each of its nodes during step k, s = signal(coefficients of channel c).
// The variables are the channels' coefficients, channel after channel;
// starting values 0. Forces add to the base setup's external forces.
class ExternalForceControl : public ControlVariables {
 public:
  struct Channel {
    std::vector<int> nodes;
    Vec3 direction = Vec3::UnitX();
    std::unique_ptr<ControlSignal> signal;
  };
  // Throws InvalidInputError if there is no channel, a channel has no node,
  // a negative node, no signal, a non-finite direction, or the signals have
  // different numbers of steps.
  explicit ExternalForceControl(std::vector<Channel> channels);
  std::string name() const override { return "external_force"; }
  int num_channels() const { return static_cast<int>(channels_.size()); }
  // First variable of channel c.
  int channel_offset(int c) const { return offsets_[c]; }
  const Channel& channel(int c) const { return channels_[c]; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override;
  bool AddDirection(const Eigen::Ref<const VectorXd>& values, int j, int num_steps,
                    InputDirection* direction) const override;

 private:
  std::vector<Channel> channels_;
  std::vector<int> offsets_;  // num_channels + 1
};

// Material (design) parameters as variables, each divided by a scale so the
// optimiser sees numbers near 1: variable = parameter / scale. Starting
// values: `start`'s parameters / scale. Apply() overwrites those fields of
// the setup's material.
class MaterialVariables : public ControlVariables {
 public:
  enum Field { kYoungsModulus, kPoissonsRatio, kDensity };
  struct Entry {
    Field field;
    double scale = 1;  // units of the parameter per variable unit (Pa, 1, kg/m^3)
  };
  // Throws InvalidInputError if entries is empty, a field repeats, or a
  // scale is not finite and > 0.
  MaterialVariables(std::vector<Entry> entries, const MaterialParameters& start);
  std::string name() const override { return "material"; }
  void CheckFits(const Scene& scene, int num_steps) const override {}
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }
  bool AddDirection(const Eigen::Ref<const VectorXd>& values, int j, int num_steps,
                    InputDirection* direction) const override;

 private:
  std::vector<Entry> entries_;
};

// Muscle activations (muscle.h) driven by control signals: channel c sets
// the activation of Scene::muscles[muscle] to s_k during step k (1 = rest,
// < 1 contracts). Muscles without a channel keep the base setup's
// activation (RolloutNlp fills a base without activations with 1). The variables are the channels'
// coefficients, channel after channel; starting values: a constant signal
// of 1 (rest). Forward mode does not cover activations: an NLP with this
// block uses reverse mode.
class ActivationControl : public ControlVariables {
 public:
  struct Channel {
    int muscle = 0;
    std::unique_ptr<ControlSignal> signal;
  };
  // Throws InvalidInputError if there is no channel, a channel has a
  // negative muscle or no signal, two channels drive the same muscle, or the
  // signals have different numbers of steps.
  explicit ActivationControl(std::vector<Channel> channels);
  std::string name() const override { return "activation"; }
  int num_channels() const { return static_cast<int>(channels_.size()); }
  int channel_offset(int c) const { return offsets_[c]; }
  const Channel& channel(int c) const { return channels_[c]; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override;

 private:
  std::vector<Channel> channels_;
  std::vector<int> offsets_;  // num_channels + 1
};

}  // namespace diffpd::solvers
