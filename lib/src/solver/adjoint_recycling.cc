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

void AdjointRecycling::Guess(const MatrixXd& b, const std::function<VectorXd(const VectorXd&)>& apply_h, MatrixXd* z0,
                             MatrixXd* r0) const {
  *z0 = MatrixXd::Zero(b.rows(), b.cols());
  *r0 = b;
  const int m = size();
  if (m == 0) return;
  MatrixXd w(b.rows(), m), hw(b.rows(), m);
  for (int j = 0; j < m; ++j) {
    w.col(j) = columns_[j];
    hw.col(j) = apply_h(columns_[j]);
  }
  // Coefficient-wise products throughout: these are thin (m columns), and
  // Eigen's blocked GEMM would open an OpenMP team for each of them.
  MatrixXd e = w.transpose().lazyProduct(hw);
  e = (0.5 * (e + e.transpose())).eval();
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(e);
  const VectorXd& values = eig.eigenvalues();
  const double floor = kRelativeEigenvalueFloor * values.cwiseAbs().maxCoeff();
  VectorXd inverse = VectorXd::Zero(m);
  for (int k = 0; k < m; ++k)
    if (values(k) > floor) inverse(k) = 1 / values(k);
  const MatrixXd projected = w.transpose().lazyProduct(b);
  const MatrixXd coefficients =
      eig.eigenvectors().lazyProduct(inverse.asDiagonal() * eig.eigenvectors().transpose().lazyProduct(projected));
  for (Eigen::Index c = 0; c < b.cols(); ++c) {
    const VectorXd residual = b.col(c) - hw.lazyProduct(coefficients.col(c));
    if (!(residual.norm() < b.col(c).norm())) continue;  // no better than zero
    z0->col(c) = w.lazyProduct(coefficients.col(c));
    r0->col(c) = residual;
  }
}

}  // namespace diffpd::internal
