// Initial guesses for a sequence of adjoint (or tangent) solves from the
// solutions of the steps solved before (internal;
// SolverOptions::adjoint_guess_solutions).
//
// The backward pass solves H_i z_i = b_i for i = K-1, ..., 0, and b_i is
// built from z_{i+1} (b_i = M z_{i+1} / h^2 + ...): consecutive adjoints
// are close, and the last few span most of the next one. The guess is the
// Galerkin projection of H_i z = b_i onto W, the span of the latest m
// solutions (columns scaled to unit norm):
//   z0 = W E^+ W^T b,  E = W^T H_i W  (m x m),
// the minimiser of the H_i-norm error over span W where H_i is positive
// definite on it (E's eigenvalues below a relative floor, or not positive,
// are dropped). The iteration then solves H_i dz = b - H_i z0 to the same
// absolute residual as from zero (the tolerance stays relative to ||b||).
// Costs m products with H_i per step, made in one pass over the element
// Hessians. A column whose guess does not reduce the residual starts from
// zero.
#pragma once

#include <deque>
#include <functional>

#include "diffpd/types.h"

namespace diffpd::internal {

class AdjointRecycling {
 public:
  // Keeps at most `capacity` (>= 0) solution columns, the latest.
  explicit AdjointRecycling(int capacity) : capacity_(capacity) {}

  // Adds a step's solution columns (each 3n; zero columns are skipped).
  void Push(const MatrixXd& solutions);
  int size() const { return static_cast<int>(columns_.size()); }

  // For the columns of b: z0 (the guesses) and r0 = b - H z0, with
  // apply_h(V) = H V for the columns of V (3n x m). Without stored columns
  // z0 = 0 and r0 = b.
  void Guess(const MatrixXd& b, const std::function<MatrixXd(const MatrixXd&)>& apply_h, MatrixXd* z0,
             MatrixXd* r0) const;

 private:
  int capacity_;
  std::deque<VectorXd> columns_;  // unit norm, latest first
};

}  // namespace diffpd::internal
