// Basic numeric types shared by the library. All quantities are SI units
// (metres, kilograms, seconds, pascals) unless a header says otherwise.
#pragma once

#include <Eigen/Dense>  // Core, LU (inverse, determinant), Geometry (cross), ...
#include <Eigen/SparseCore>

namespace diffpd {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec9 = Eigen::Matrix<double, 9, 1>;
// Derivative of a 3x3 matrix w.r.t. a 3x3 matrix, both flattened column-major:
// (d vec(P) / d vec(F))(i + 3 j, k + 3 l) = dP_ij / dF_kl.
using Mat9 = Eigen::Matrix<double, 9, 9>;
using VectorXd = Eigen::VectorXd;
using MatrixXd = Eigen::MatrixXd;
using SparseMatrix = Eigen::SparseMatrix<double>;  // column-major, int indices

}  // namespace diffpd
