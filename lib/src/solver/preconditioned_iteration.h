// Iterative solves of H Z = B (the exact step Hessian, several right-hand
// sides) preconditioned by the PD matrix A, as the PD backward and tangent
// passes use them. H is only applied (element by element), never assembled.
//
// The columns advance in lockstep so that each iteration makes one batched
// A^{-1} solve for all columns still running. Methods (PdBackwardMethod):
//   kFixedPoint          z += A^{-1} (b - H z), the DiffPD iteration; fails on
//                        residual growth (spectral radius of I - A^{-1} H >= 1)
//                        or stagnation;
//   kLbfgs               L-BFGS on 1/2 z^T H z - b^T z with H0 = A^{-1} and
//                        exact steps; fails on negative curvature;
//   kConjugateGradient   CG preconditioned by A^{-1}. On a quadratic with
//                        exact steps L-BFGS and PCG produce the same iterates
//                        (in exact arithmetic, for any history length), so
//                        the iteration counts match; CG skips the two-loop
//                        recursion's 4m vector passes per iteration. Fails
//                        on negative curvature.
// A column converges when ||b - H z|| <= rel_tolerance ||b|| (or
// rel_tolerance times its reference norm, when given: a correction solve
// after an initial guess, whose b is that guess's residual), confirmed by a
// recomputed (not recurred) residual; a column already within it takes no
// iteration. Failed columns are left to the caller (the direct fallback).
#pragma once

#include <functional>
#include <vector>

#include "diffpd/solver_options.h"
#include "diffpd/types.h"

namespace diffpd::internal {

struct PreconditionedSolveOptions {
  PdBackwardMethod method = PdBackwardMethod::kConjugateGradient;
  double rel_tolerance = 1e-10;
  int max_iterations = 1000;
  int lbfgs_history = 20;  // kLbfgs only
  // Per column, the norm the tolerance is relative to; empty: ||b_c||.
  VectorXd reference_norms;
};

// apply_h(v): H v, zero at fixed DoFs; precondition(R): A^{-1} R column by
// column, zero at fixed DoFs. B's fixed rows must be zero. Fills Z (B's
// shape; zero columns for failed ones), ok[c] (column c converged) and adds
// the A^{-1} column solves made to *iterations.
void SolvePreconditioned(const PreconditionedSolveOptions& options, const MatrixXd& b,
                         const std::function<VectorXd(const VectorXd&)>& apply_h,
                         const std::function<MatrixXd(const MatrixXd&)>& precondition, MatrixXd* z,
                         std::vector<char>* ok, int* iterations);

}  // namespace diffpd::internal
