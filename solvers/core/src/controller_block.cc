#include "diffpd/solvers/core/controller_block.h"

#include "diffpd/error.h"

namespace diffpd::solvers {

ControllerBlock::ControllerBlock(const Controller& controller)
    : ParameterBlock(controller.num_parameters()), prototype_(controller.Clone()) {
  if (prototype_->num_parameters() < 1) throw InvalidInputError("controller: the controller has no parameters");
  SetInitial(prototype_->parameters());
}

void ControllerBlock::Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const {
  if (setup->controller)
    throw InvalidInputError("controller: the setup has a controller already; a rollout takes one ControllerBlock");
  std::unique_ptr<Controller> controller = prototype_->Clone();
  controller->SetParameters(values);
  setup->controller = std::shared_ptr<const Controller>(std::move(controller));
}

void ControllerBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                               Eigen::Ref<VectorXd> out) const {
  if (grad.controller_parameters.size() != size())
    throw InvalidInputError("controller: the rollout gradient has no controller parameters (an open-loop pass)");
  out = grad.controller_parameters;
}

void ControllerBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                                  InputDirection* direction) const {
  throw InvalidInputError("controller: forward mode is not available for controller parameters");
}

}  // namespace diffpd::solvers
