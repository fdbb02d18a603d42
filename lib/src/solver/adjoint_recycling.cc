#include "solver/adjoint_recycling.h"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace diffpd::internal {
namespace {

// E's eigenvalues below this fraction of its largest are dropped (solutions
// that are nearly linearly dependent).
constexpr double kRelativeEigenvalueFloor = 1e-10;

}  // namespace

void AdjointRecycling::Push(const MatrixXd& solutions) {
  if (capacity_ <= 0) return;
  for (Eigen::Index c = 0; c < solutions.cols(); ++c) {
    const double norm = solutions.col(c).norm();
    if (!(norm > 0) || !std::isfinite(norm)) continue;
    columns_.push_front(solutions.col(c) / norm);
    if (static_cast<int>(columns_.size()) > capacity_) columns_.pop_back();
  }
}

void AdjointRecycling::Guess(const MatrixXd& b, const std::function<MatrixXd(const MatrixXd&)>& apply_h, MatrixXd* z0,
                             MatrixXd* r0) const {
  *z0 = MatrixXd::Zero(b.rows(), b.cols());
  *r0 = b;
  const int m = size();
  if (m == 0) return;
  MatrixXd w(b.rows(), m);
  for (int j = 0; j < m; ++j) w.col(j) = columns_[j];
  const MatrixXd hw = apply_h(w);
  // Dot products and matrix-vector products throughout: these are thin (m
  // columns), and Eigen's blocked GEMM would open an OpenMP team for each.
  Eigen::MatrixXd e(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j <= i; ++j) e(i, j) = e(j, i) = 0.5 * (w.col(i).dot(hw.col(j)) + w.col(j).dot(hw.col(i)));
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(e);
  const VectorXd& values = eig.eigenvalues();
  const double floor = kRelativeEigenvalueFloor * values.cwiseAbs().maxCoeff();
  VectorXd inverse = VectorXd::Zero(m);
  for (int k = 0; k < m; ++k)
    if (values(k) > floor) inverse(k) = 1 / values(k);
  for (Eigen::Index c = 0; c < b.cols(); ++c) {
    VectorXd projected(m);
    for (int j = 0; j < m; ++j) projected(j) = w.col(j).dot(b.col(c));
    const VectorXd coefficients =
        eig.eigenvectors() * inverse.asDiagonal() * (eig.eigenvectors().transpose() * projected);
    VectorXd residual = b.col(c);
    residual.noalias() -= hw * coefficients;
    if (!(residual.norm() < b.col(c).norm())) continue;  // no better than zero
    z0->col(c).noalias() = w * coefficients;
    r0->col(c) = residual;
  }
}

}  // namespace diffpd::internal
