// The initial state of a body as a rigid placement and a common velocity,
// 9 variables (roll, pitch, yaw, c_x, c_y, c_z, u_x, u_y, u_z):
//
//   x_i = R (X_i - Xbar) + c,   v_i = base v_i + u,
//   R = R_z(yaw) R_y(pitch) R_x(roll),
//
// X the rest positions given at construction (3n, m), Xbar their unweighted
// mean, angles in rad, c in m, u in m/s (the paper's bunny row). Gradient:
// dL/dangle = sum_i dL/dx_i . (dR/dangle)(X_i - Xbar), dL/dc = sum_i dL/dx_i,
// dL/du = sum_i dL/dv_i.
#pragma once

#include <string>

#include "paper/reverse_mode_block.h"

namespace diffpd::problems {

class RigidPlacementVariables : public ReverseModeBlock {
 public:
  // Throws InvalidInputError if rest_positions is empty or not of size 3n.
  explicit RigidPlacementVariables(const VectorXd& rest_positions);
  std::string name() const override { return "rigid_placement"; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  // Overwrites setup->initial.x and adds u to every velocity.
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 0; }

  // R_z(yaw) R_y(pitch) R_x(roll) and, if wanted, its derivatives w.r.t.
  // roll, pitch and yaw (derivatives may be nullptr).
  static Mat3 Rotation(const Vec3& roll_pitch_yaw, Mat3 derivatives[3] = nullptr);

 private:
  Eigen::Matrix3Xd offsets_;  // X_i - Xbar
};

}  // namespace diffpd::problems
