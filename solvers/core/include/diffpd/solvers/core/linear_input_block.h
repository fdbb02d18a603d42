// Inputs affine in q parameters, with arbitrary spatial bases:
//   x_0 += X p,  v_0 += V p,  f_k += F p for steps force_begin <= k < force_end
// (X, V, F: 3n x q; m, m/s and N per parameter unit). Steps at or beyond the
// rollout's K are ignored. Starting values 0.
#pragma once

#include <string>

#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::solvers {

class LinearInputBlock : public ParameterBlock {
 public:
  // A basis may be empty (0 x 0); the others have the same number of
  // columns q >= 1 and 3 x (number of nodes) rows. Throws InvalidInputError,
  // e.g. "velocity_basis has 3 columns, but another basis has 2",
  // "position_basis has 7 rows, expected 3 x number of nodes",
  // "force_basis has a non-finite entry",
  // "linear_input: no basis with at least one column given",
  // "force_begin = 3, force_end = 2 is invalid: need 0 <= begin <= end".
  LinearInputBlock(MatrixXd position_basis, MatrixXd velocity_basis, MatrixXd force_basis = MatrixXd(),
                   int force_begin = 0, int force_end = 0);
  std::string name() const override { return "linear_input"; }
  // Throws InvalidInputError "linear_input: a basis has 6 rows but the scene has 135 DoFs".
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override;
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                   InputDirection* direction) const override;

 private:
  MatrixXd position_, velocity_, force_;
  int force_begin_, force_end_;
};

}  // namespace diffpd::solvers
