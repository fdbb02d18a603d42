// A controller's parameters (e.g. a network's weights, controller.h) as a
// parameter block: the rollouts become closed-loop (Simulator::Simulate with
// the controller), and the block's gradient is the reverse pass's
// dL/d(controller parameters).
//
//   RolloutFunction f(scene, options, 200);
//   f.AddBlock(std::make_unique<ControllerBlock>(network_controller));   // starting values: its parameters
//   const int loss = f.AddFunctional(std::make_unique<SwimLossFunction>(...));
//
// A rollout takes at most one ControllerBlock. The controller's actions
// replace the setup's per-step inputs (blocks that write activations or
// external forces have no effect on a closed-loop rollout). Forward mode is
// not available (Simulator::Tangents has no closed loop).
#pragma once

#include <memory>
#include <string>

#include "diffpd/controller.h"
#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::solvers {

class ControllerBlock : public ParameterBlock {
 public:
  // Keeps a copy of `controller` (Controller::Clone); the starting values are
  // its parameters. Throws InvalidInputError for a controller without
  // parameters ("controller: the controller has no parameters").
  explicit ControllerBlock(const Controller& controller);
  std::string name() const override { return "controller"; }
  const Controller& controller() const { return *prototype_; }

  // Nothing to check before a rollout: Simulator::Simulate checks each
  // action against the scene (activation per muscle, force per DoF).
  void CheckFits(const Scene& scene, int num_steps) const override {}
  // Sets setup->controller to a copy of the controller with `values` as its
  // parameters. Throws InvalidInputError if the setup has a controller
  // already ("controller: the setup has a controller already; a rollout
  // takes one ControllerBlock").
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  // out = grad.controller_parameters.
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  // The parameters act from the first step on.
  int FirstAffectedState(int j) const override { return 1; }
  bool SupportsForwardMode() const override { return false; }
  // Never called (SupportsForwardMode is false); throws InvalidInputError.
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                   InputDirection* direction) const override;

 private:
  std::unique_ptr<Controller> prototype_;
};

}  // namespace diffpd::solvers
