// A block of optimisation parameters: it owns a slice of the optimiser's
// vector, writes it into what a rollout is made from (RolloutSetup), pulls a
// rollout gradient back onto its slice (reverse mode) and pushes a direction
// forward into the simulator's input directions (forward mode).
//
//   auto v0 = std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, all_nodes);
//   v0->SetBounds(-2.0, 2.0);                          // m/s
//   rollout_function.AddBlock(std::move(v0));          // rollout_function.h
//
// The blocks of the library: InitialStateBlock, LinearInputBlock,
// ExternalForceBlock, ActivationBlock (per-step and signal-parametrised
// inputs), MaterialBlock (base and per-region E, nu, rho), StateForceBlock
// (damping, hydrodynamics, penalty friction), ControllerBlock (a closed-loop
// controller's weights). A new kind of input (an actuation model mapping a
// few parameters to activations) is a new subclass: Apply writes the setup,
// PullBack applies the transpose of d(setup)/d(values) to the simulator's
// RolloutGradient, PushForward applies d(setup)/d(values) to a unit vector.
#pragma once

#include <limits>
#include <string>

#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/solvers/core/rollout_setup.h"
#include "diffpd/tangent_rollout.h"
#include "diffpd/types.h"

namespace diffpd::solvers {

// FirstAffectedState of a parameter that affects no state.
inline constexpr int kAffectsNoState = std::numeric_limits<int>::max();

class ParameterBlock {
 public:
  virtual ~ParameterBlock() = default;
  // Names the block in messages ("initial_velocity", "material", ...).
  virtual std::string name() const = 0;
  int size() const { return static_cast<int>(initial_.size()); }

  // Bounds (units of the block's parameters; +-infinity: none) and starting
  // values. Defaults: unbounded, the starting values the block chose.
  // Throw InvalidInputError on a size mismatch, NaN, or lower > upper.
  void SetBounds(double lower, double upper);
  void SetBounds(int offset, int count, double lower, double upper);
  void SetInitial(const VectorXd& values);
  const VectorXd& lower() const { return lower_; }
  const VectorXd& upper() const { return upper_; }
  const VectorXd& initial() const { return initial_; }

  // Throws InvalidInputError if the block does not fit a rollout of `scene`
  // with `num_steps` steps (node, muscle or region out of range, signal of
  // another length, a state force the scene does not declare).
  virtual void CheckFits(const Scene& scene, int num_steps) const = 0;
  // Writes the effect of `values` (size()) into `setup`. May throw
  // InvalidInputError for values outside the block's domain.
  virtual void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const = 0;
  // out (size()) = dL/d(values), given the gradient of L w.r.t. the rollout's
  // inputs at the setup made from `values`. The per-step lists of `grad` may
  // hold fewer than K steps (a rollout truncated after the loss's last
  // state): the missing steps have zero gradient.
  virtual void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                        Eigen::Ref<VectorXd> out) const = 0;
  // The earliest state index k (0..K) that parameter j can influence: 0 for
  // the initial state, i + 1 for an input of step i, kAffectsNoState for none.
  // Used to declare Jacobian sparsity.
  virtual int FirstAffectedState(int j) const = 0;
  // Whether PushForward is available (a block whose setup change has no
  // InputDirection, e.g. one that changes the mesh, returns false).
  virtual bool SupportsForwardMode() const { return true; }
  // Adds d(setup)/d(values_j) into `direction`, whose lists are sized for
  // `setup` (the setup at `values`): x0 and v0 3n (zero), external_force and
  // activation one entry per step (empty: zero; an activation entry, once
  // filled, has one value per muscle), region_materials one per region,
  // state_forces zero (penalty_friction empty). Only called when
  // SupportsForwardMode().
  virtual void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                           InputDirection* direction) const = 0;

 protected:
  explicit ParameterBlock(int size);
  // Adds `count` unbounded parameters with starting value 0 at the end.
  void Append(int count);

 private:
  VectorXd lower_, upper_, initial_;
};

}  // namespace diffpd::solvers
