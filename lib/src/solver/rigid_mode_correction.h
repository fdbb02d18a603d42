// The body's rigid modes as a coarse correction of PD's preconditioner
// (internal; SolverOptions::rigid_mode_correction).
//
// PD's matrix A = M/h^2 + sum_s w_s G_s^T G_s charges a rigid rotation of the
// body as a stretch (the deformation gradient of a rotated body is the
// rotation, not zero), while the step Hessian H = M/h^2 + hess E resists
// rigid motion with inertia alone. For a body that is free to move (a ball on
// the ground, a swimmer) the rigid modes are H's softest directions and A^-1
// is furthest from H^-1 exactly there: PD-LBFGS and the PD backward's CG
// spend most of their iterations recovering them. The additive two-level
// preconditioner
//   P^-1 r = A^-1 r + Z (Z^T H Z)^+ Z^T r,
// with Z the 6 rigid modes (3 translations, 3 rotations about the nodes'
// centroid) zeroed at fixed DoFs, treats them with H's own 6 x 6 Galerkin
// matrix. P^-1 is symmetric positive definite (A^-1 is, the correction is
// positive semi-definite), so it is a valid L-BFGS initial inverse Hessian
// and CG preconditioner. E = Z^T H Z's non-positive eigenvalues (H indefinite
// along a mode) are dropped from the pseudo-inverse. Used for bodies without
// Dirichlet DoFs only (SimulatorImpl::UseRigidModeCorrection): a clamped
// body's cut modes are not soft, and there it cost accuracy
// (docs/benchmarks.md).
#pragma once

#include <vector>

#include "diffpd/types.h"

namespace diffpd::internal {

class SimulatorImpl;

class RigidModeCorrection {
 public:
  static constexpr int kModes = 6;

  // The modes at positions x (3n), zero at the DoFs flagged in `fixed`
  // (3n flags), each column scaled to unit norm.
  RigidModeCorrection(const VectorXd& x, const std::vector<char>& fixed);

  // Z (3n x 6).
  const MatrixXd& modes() const { return modes_; }
  // The uncut modes (3n x 6, nothing zeroed, not normalised): translations
  // e_a, then rotations e_a x (x_i - c), a = x, y, z; Z = P uncut diag(scale)
  // with P zeroing the fixed DoFs.
  const MatrixXd& uncut_modes() const { return uncut_; }
  const Eigen::Matrix<double, kModes, 1>& scale() const { return scale_; }
  // Sets E = Z^T (H Z) from hz = H Z (3n x 6, fixed rows ignored).
  void SetHessianProducts(const MatrixXd& hz);
  // out += Z E^+ Z^T r for each column of r (3n x P, out the same shape).
  void Add(const MatrixXd& r, MatrixXd* out) const;
  void Add(const VectorXd& r, VectorXd* out) const;

 private:
  MatrixXd uncut_;
  Eigen::Matrix<double, kModes, 1> scale_ = Eigen::Matrix<double, kModes, 1>::Zero();
  MatrixXd modes_;
  Eigen::Matrix<double, kModes, kModes> pseudo_inverse_ = Eigen::Matrix<double, kModes, kModes>::Zero();
};

// H Z for `rigid`'s modes at x, H the step Hessian over the free DoFs
// (diagonal `inertia` (3n) + elastic + auxiliary energies), without
// differentiating the elastic energy along the modes: being frame
// indifferent, E has H_E t = 0 for a translation t and, for a rotation,
// H_E (e_a x (x_i - c))_i = (e_a x grad_i E)_i. Only the elements with a
// fixed DoF, where Z was cut, need their Hessians (the cut part
// uncut - P uncut lives on the fixed DoFs). `elastic_gradient` is grad E(x)
// (3n; its fixed rows are not read). Costs those elements' Hessians and 6
// auxiliary Hessian products, far less than differencing the gradient along
// the 6 modes (6 gradient evaluations).
MatrixXd RigidModeHessianProducts(SimulatorImpl& sim, const RigidModeCorrection& rigid, const VectorXd& x,
                                  const VectorXd& elastic_gradient, const VectorXd& inertia);

}  // namespace diffpd::internal
