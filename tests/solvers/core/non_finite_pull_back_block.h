// A parameter block whose reverse-mode derivative is NaN: it wraps another
// block and overwrites the first entry of every PullBack with NaN (reverse
// mode only). The optimiser adapters must report such an evaluation as
// failed rather than hand the NaN to Ceres or Ipopt.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::testing {

class NonFinitePullBackBlock : public solvers::ParameterBlock {
 public:
  explicit NonFinitePullBackBlock(std::unique_ptr<solvers::ParameterBlock> inner)
      : solvers::ParameterBlock(inner->size()), inner_(std::move(inner)) {
    SetInitial(inner_->initial());
  }
  std::string name() const override { return "non_finite_pull_back"; }
  void CheckFits(const Scene& scene, int num_steps) const override { inner_->CheckFits(scene, num_steps); }
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override {
    inner_->Apply(values, setup);
  }
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override {
    inner_->PullBack(values, grad, out);
    out(0) = std::numeric_limits<double>::quiet_NaN();
  }
  int FirstAffectedState(int j) const override { return inner_->FirstAffectedState(j); }
  bool SupportsForwardMode() const override { return false; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const solvers::RolloutSetup& setup,
                   InputDirection* direction) const override {
    ADD_FAILURE() << "PushForward of a block without forward mode";
  }

 private:
  std::unique_ptr<solvers::ParameterBlock> inner_;
};

}  // namespace diffpd::testing
