// Initial positions (m) or velocities (m/s) of a set of nodes as parameters.
#pragma once

#include <string>
#include <vector>

#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::solvers {

// Either one 3-vector shared by all the nodes (kShared: 3 parameters, a rigid
// shift of the positions or a common velocity) or one 3-vector per node
// (kPerNode: 3 parameters per node, node-major). The values are added to the
// setup's x_0 or v_0; starting values 0.
class InitialStateBlock : public ParameterBlock {
 public:
  enum Quantity { kPosition, kVelocity };
  enum Sharing { kShared, kPerNode };
  // Throws InvalidInputError if nodes is empty or has a negative index.
  InitialStateBlock(Quantity quantity, std::vector<int> nodes, Sharing sharing = kShared);
  // "initial_position" or "initial_velocity".
  std::string name() const override;
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 0; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                   InputDirection* direction) const override;

 private:
  Quantity quantity_;
  std::vector<int> nodes_;
  Sharing sharing_;
};

}  // namespace diffpd::solvers
