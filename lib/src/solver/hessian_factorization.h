// Direct solves with an assembled step Hessian (3n x 3n, symmetric;
// internal): Newton's linear systems and the direct adjoint and tangent
// solves of every method share one of these per simulator.
//
// Two factorisations:
//   kCholmodSupernodal  CHOLMOD's supernodal LL^T (newton-cholesky, and the
//                       PD methods' direct adjoint). The fill-reducing
//                       ordering and symbolic analysis are made once per
//                       sparsity pattern (the assembled Hessian keeps one
//                       pattern for the simulator's lifetime, fixed DoFs as
//                       explicit zeros), each Factorize redoes only the
//                       numeric factorisation.
//   kSimplicialLdlt     Eigen's simplicial LDL^T under AMD ordering
//                       (newton-ldlt): what the DiffPD paper's Newton used,
//                       a fresh Eigen::SimplicialLDLT per solve, so ordering
//                       and symbolic analysis are redone at every
//                       factorisation, as there.
#pragma once

#include <memory>

#include <Eigen/SparseCholesky>

#include "diffpd/types.h"
#include "solver/cholmod_solver.h"

namespace diffpd::internal {

enum class HessianFactorizationKind { kCholmodSupernodal, kSimplicialLdlt };

class HessianFactorization {
 public:
  explicit HessianFactorization(HessianFactorizationKind kind);
  HessianFactorization(const HessianFactorization&) = delete;
  HessianFactorization& operator=(const HessianFactorization&) = delete;

  HessianFactorizationKind kind() const { return kind_; }
  // Factorises the symmetric matrix h (its lower triangle is read). Returns
  // false when h is not positive definite (LL^T) or meets a zero pivot
  // (LDL^T, which also factorises indefinite matrices); Solve must not be
  // called after a failure.
  bool Factorize(const SparseMatrix& h);
  // Solves H X = B for one or several right-hand sides.
  VectorXd Solve(const VectorXd& b) const;
  MatrixXd Solve(const MatrixXd& b) const;

  // Factorisations so far, successful or not: a user that factorised at
  // count c knows the factor is still its own while the count is c.
  int num_factorizations() const { return num_factorizations_; }
  // Symbolic analyses so far (kCholmodSupernodal: one per pattern;
  // kSimplicialLdlt: one per factorisation).
  int num_analyses() const;
  // kCholmodSupernodal after an analysis: the factor's entries and the flops
  // of one numeric factorisation (CholmodSolver); 0 otherwise.
  double factor_nonzeros() const;
  double factor_flops() const;
  // Wall seconds of the latest Factorize, and the part of them spent on the
  // ordering and symbolic analysis (0 when it reused an earlier analysis).
  double factorize_seconds() const { return factorize_seconds_; }
  double analysis_seconds() const { return analysis_seconds_; }

 private:
  HessianFactorizationKind kind_;
  std::unique_ptr<CholmodSolver> cholmod_;
  std::unique_ptr<Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>>> ldlt_;
  int num_factorizations_ = 0;
  int num_ldlt_analyses_ = 0;
  bool factorized_ = false;
  double factorize_seconds_ = 0;
  double analysis_seconds_ = 0;
};

}  // namespace diffpd::internal
