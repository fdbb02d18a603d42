#include "limited_memory_matrix.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <limits>

namespace diffpd::solvers::lbfgsb_internal {

LimitedMemoryMatrix::LimitedMemoryMatrix(int n, int memory)
    : n_(n), memory_(memory), s_(n, memory), y_(n, memory), w_(n, 0), m_(0, 0) {}

void LimitedMemoryMatrix::Reset() {
  k_ = 0;
  theta_ = 1;
  w_.resize(n_, 0);
  m_.resize(0, 0);
}

bool LimitedMemoryMatrix::Update(const VectorXd& s, const VectorXd& y) {
  const double sy = s.dot(y);
  const double yy = y.squaredNorm();
  if (!(sy > std::numeric_limits<double>::epsilon() * yy) || !std::isfinite(sy) || !std::isfinite(yy)) return false;
  const MatrixXd old_s = s_, old_y = y_;
  const int old_k = k_;
  const double old_theta = theta_;
  if (k_ == memory_) {
    // Drop the oldest pair.
    s_.leftCols(memory_ - 1) = old_s.rightCols(memory_ - 1);
    y_.leftCols(memory_ - 1) = old_y.rightCols(memory_ - 1);
    --k_;
  }
  s_.col(k_) = s;
  y_.col(k_) = y;
  ++k_;
  theta_ = yy / sy;
  if (Rebuild()) return true;
  s_ = old_s;
  y_ = old_y;
  k_ = old_k;
  theta_ = old_theta;
  Rebuild();
  return false;
}

bool LimitedMemoryMatrix::Rebuild() {
  if (k_ == 0) {
    Reset();
    return true;
  }
  const auto S = s_.leftCols(k_);
  const auto Y = y_.leftCols(k_);
  const MatrixXd sty = S.transpose() * Y;
  const MatrixXd sts = S.transpose() * S;
  const VectorXd d = sty.diagonal();  // > 0: each pair passed the curvature test
  MatrixXd l = MatrixXd::Zero(k_, k_);
  for (int i = 0; i < k_; ++i)
    for (int j = 0; j < i; ++j) l(i, j) = sty(i, j);
  const VectorXd d_inv = d.cwiseInverse();
  // T = theta S^T S + L D^-1 L^T, the Schur complement of -D.
  const MatrixXd t = theta_ * sts + l * d_inv.asDiagonal() * l.transpose();
  Eigen::LLT<MatrixXd> llt(t);
  if (llt.info() != Eigen::Success) return false;
  const MatrixXd t_inv = llt.solve(MatrixXd::Identity(k_, k_));
  // The block inverse of [[-D, L^T], [L, T0]] through T:
  //   [[-D^-1 + D^-1 L^T T^-1 L D^-1, D^-1 L^T T^-1], [T^-1 L D^-1, T^-1]].
  const MatrixXd dl = d_inv.asDiagonal() * l.transpose();  // D^-1 L^T
  MatrixXd m(2 * k_, 2 * k_);
  m.topLeftCorner(k_, k_) = dl * t_inv * dl.transpose();
  m.topLeftCorner(k_, k_).diagonal() -= d_inv;
  m.topRightCorner(k_, k_) = dl * t_inv;
  m.bottomLeftCorner(k_, k_) = t_inv * dl.transpose();
  m.bottomRightCorner(k_, k_) = t_inv;
  if (!m.allFinite()) return false;
  w_.resize(n_, 2 * k_);
  w_.leftCols(k_) = Y;
  w_.rightCols(k_) = theta_ * S;
  m_ = m;
  return true;
}

}  // namespace diffpd::solvers::lbfgsb_internal
