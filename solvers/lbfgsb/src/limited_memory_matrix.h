// The compact representation of the limited-memory BFGS matrix (Byrd,
// Nocedal and Schnabel 1994, as L-BFGS-B uses it):
//
//   B = theta I - W M W^T,   W = [Y, theta S]   (n x 2k),
//   M = [ -D   L^T       ]^-1
//       [  L   theta S^T S]
//
// S, Y: the k <= memory latest pairs s_i = x_i+1 - x_i, y_i = g_i+1 - g_i
// (oldest first), D = diag(s_i^T y_i), L the strictly lower triangle of
// S^T Y, theta = y^T y / s^T y of the latest pair (1 with no pair). M is
// formed by block elimination through the Cholesky factor of
// theta S^T S + L D^-1 L^T.
#pragma once

#include "diffpd/types.h"

namespace diffpd::solvers::lbfgsb_internal {

class LimitedMemoryMatrix {
 public:
  LimitedMemoryMatrix(int n, int memory);

  // Stores the pair (dropping the oldest when full) if s^T y > eps y^T y
  // and the middle matrix stays invertible; returns whether it did (the
  // matrix is unchanged otherwise).
  bool Update(const VectorXd& s, const VectorXd& y);
  // Forgets every pair (B = I).
  void Reset();

  int pairs() const { return k_; }
  double theta() const { return theta_; }
  // n x 2k and 2k x 2k (empty with no pair).
  const MatrixXd& W() const { return w_; }
  const MatrixXd& M() const { return m_; }

 private:
  bool Rebuild();

  int n_, memory_;
  int k_ = 0;
  double theta_ = 1;
  MatrixXd s_, y_;  // n x memory, the first k_ columns used
  MatrixXd w_, m_;
};

}  // namespace diffpd::solvers::lbfgsb_internal
