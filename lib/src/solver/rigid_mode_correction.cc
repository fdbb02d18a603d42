#include "solver/rigid_mode_correction.h"

#include <Eigen/Eigenvalues>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

// Eigenvalues of E below this fraction of its largest are dropped (rounding
// of modes the fixed DoFs nearly removed).
constexpr double kRelativeEigenvalueFloor = 1e-12;

}  // namespace

RigidModeCorrection::RigidModeCorrection(const VectorXd& x, const std::vector<char>& fixed) {
  const Eigen::Index dofs = x.size();
  DIFFPD_CHECK(dofs % 3 == 0 && static_cast<Eigen::Index>(fixed.size()) == dofs,
               "RigidModeCorrection: " << dofs << " positions, " << fixed.size() << " flags");
  const Eigen::Index n = dofs / 3;
  Vec3 centre = Vec3::Zero();
  for (Eigen::Index i = 0; i < n; ++i) centre += x.segment<3>(3 * i);
  if (n > 0) centre /= static_cast<double>(n);
  modes_ = MatrixXd::Zero(dofs, kModes);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 p = x.segment<3>(3 * i) - centre;
    for (int a = 0; a < 3; ++a) {
      modes_(3 * i + a, a) = 1;                                          // translation along a
      modes_.block<3, 1>(3 * i, 3 + a) = Vec3::Unit(a).cross(p);         // rotation about a
    }
  }
  for (Eigen::Index d = 0; d < dofs; ++d)
    if (fixed[d]) modes_.row(d).setZero();
  for (int k = 0; k < kModes; ++k) {
    const double norm = modes_.col(k).norm();
    if (norm > 0) modes_.col(k) /= norm;
  }
}

void RigidModeCorrection::SetHessianProducts(const MatrixXd& hz) {
  DIFFPD_CHECK(hz.rows() == modes_.rows() && hz.cols() == kModes,
               "RigidModeCorrection: H Z is " << hz.rows() << " x " << hz.cols());
  Eigen::Matrix<double, kModes, kModes> e = modes_.transpose() * hz;
  e = (0.5 * (e + e.transpose())).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, kModes, kModes>> eig(e);
  const auto& values = eig.eigenvalues();
  const double floor = kRelativeEigenvalueFloor * values.cwiseAbs().maxCoeff();
  Eigen::Matrix<double, kModes, 1> inverse = Eigen::Matrix<double, kModes, 1>::Zero();
  for (int k = 0; k < kModes; ++k)
    if (values(k) > floor) inverse(k) = 1 / values(k);
  pseudo_inverse_ = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
}

void RigidModeCorrection::Add(const MatrixXd& r, MatrixXd* out) const {
  *out += modes_ * (pseudo_inverse_ * (modes_.transpose() * r));
}

void RigidModeCorrection::Add(const VectorXd& r, VectorXd* out) const {
  *out += modes_ * (pseudo_inverse_ * (modes_.transpose() * r));
}

}  // namespace diffpd::internal
