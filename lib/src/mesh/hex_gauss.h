// Trilinear hexahedron geometry at the 2x2x2 Gauss points (internal).
//
// Local node a = 4 i + 2 j + k sits at the reference corner
// (xi, eta, zeta) = (2i-1, 2j-1, 2k-1); Gauss point g = 4 p + 2 q + r sits at
// ((2p-1), (2q-1), (2r-1)) / sqrt(3), weight 1. Shape functions:
//   N_a = (1 + xi_a xi)(1 + eta_a eta)(1 + zeta_a zeta) / 8.
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace diffpd::internal {

// Reference coordinates of Gauss point g (0..7).
inline Eigen::Vector3d HexGaussPoint(int g) {
  const double c = 1.0 / std::sqrt(3.0);
  return Eigen::Vector3d(((g >> 2) & 1) ? c : -c, ((g >> 1) & 1) ? c : -c, (g & 1) ? c : -c);
}

// 8 x 3 matrix of dN_a / d(xi, eta, zeta) at reference point xi.
inline Eigen::Matrix<double, 8, 3> HexShapeGradients(const Eigen::Vector3d& xi) {
  Eigen::Matrix<double, 8, 3> grad;
  for (int a = 0; a < 8; ++a) {
    const Eigen::Vector3d s(((a >> 2) & 1) ? 1.0 : -1.0, ((a >> 1) & 1) ? 1.0 : -1.0, (a & 1) ? 1.0 : -1.0);
    const Eigen::Vector3d f = (Eigen::Vector3d::Ones() + s.cwiseProduct(xi));
    grad(a, 0) = s(0) * f(1) * f(2) / 8.0;
    grad(a, 1) = f(0) * s(1) * f(2) / 8.0;
    grad(a, 2) = f(0) * f(1) * s(2) / 8.0;
  }
  return grad;
}

// Jacobian d x / d(xi, eta, zeta) (3 x 3) of hex element e at Gauss point g;
// `positions` is 3 x n, `elements` 8 x m.
inline Eigen::Matrix3d HexJacobian(const Eigen::Matrix3Xd& positions, const Eigen::MatrixXi& elements, int e, int g) {
  const Eigen::Matrix<double, 8, 3> grad = HexShapeGradients(HexGaussPoint(g));
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 8; ++a) jacobian += positions.col(elements(a, e)) * grad.row(a);
  return jacobian;
}

}  // namespace diffpd::internal
