// A parameter block of the paper rows that is differentiated in reverse mode
// only (the rows' optimiser needs one gradient per evaluation, not tangents):
// SupportsForwardMode() is false and PushForward throws std::logic_error
// (callers must not call it for such a block, parameter_block.h).
#pragma once

#include <stdexcept>
#include <string>

#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::problems {

class ReverseModeBlock : public solvers::ParameterBlock {
 public:
  bool SupportsForwardMode() const final { return false; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const solvers::RolloutSetup& setup,
                   InputDirection* direction) const final {
    throw std::logic_error(name() + ": forward mode is not supported (SupportsForwardMode() is false)");
  }

 protected:
  explicit ReverseModeBlock(int size) : ParameterBlock(size) {}
};

}  // namespace diffpd::problems
