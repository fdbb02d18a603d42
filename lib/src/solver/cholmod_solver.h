// Sparse Cholesky by CHOLMOD (internal). The symbolic analysis
// (fill-reducing ordering) is done once per sparsity pattern; Factorize()
// then only redoes the numeric factorisation.
//
// Two factor layouts: supernodal (dense BLAS blocks: the fastest
// factorisation, used where a matrix is factorised every iteration, Newton)
// and simplicial (column by column, no BLAS call per supernode, so each solve
// is cheaper on meshes up to tens of thousands of nodes: the PD matrix,
// factorised once and solved with at every iteration; see PdSystem).
#pragma once

#include <memory>

#include "diffpd/types.h"

namespace diffpd::internal {

enum class CholmodLayout { kSupernodal, kSimplicial };

// Fill-reducing ordering. kAutomatic: CHOLMOD's default (AMD, then METIS if
// AMD's fill looks poor). kNestedDissection: CHOLMOD's nested dissection
// (NESDIS) always. On the PD matrix of hexahedral meshes (27-point stencil,
// scalar n x n) the default keeps AMD, with 25-40% more factor entries than
// nested dissection from 2 673 to 9 945 nodes (cantilever 1x-4x: 290 k vs
// 217 k, 638 k vs 472 k, 2.12 M vs 1.26 M) and twice the factorisation
// flops; at 18 785 nodes it picks METIS itself. On Newton's 3n x 3n matrix
// it already picks METIS (2.00 M entries at 8 019 DoFs; NESDIS 1.95 M).
enum class CholmodOrdering { kAutomatic, kNestedDissection };

class CholmodSolver {
 public:
  explicit CholmodSolver(CholmodLayout layout = CholmodLayout::kSupernodal,
                         CholmodOrdering ordering = CholmodOrdering::kAutomatic);
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  // Numeric factorisation of the symmetric matrix `a` (its lower triangle is
  // read). The pattern is analysed on the first call and whenever it changes
  // (different size or number of non-zeros). Returns false if `a` is not
  // positive definite.
  bool Factorize(const SparseMatrix& a);
  // Solves A X = B for one or several right-hand sides (columns of B).
  MatrixXd Solve(const MatrixXd& b) const;
  VectorXd Solve(const VectorXd& b) const;

  CholmodLayout layout() const { return layout_; }
  int num_analyses() const { return num_analyses_; }
  // Entries of the factor L after the latest analysis (CHOLMOD's lnz).
  double factor_nonzeros() const;
  int num_factorizations() const { return num_factorizations_; }
  bool factorized() const { return factorized_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  CholmodLayout layout_;
  Eigen::Index rows_ = -1;
  Eigen::Index nonzeros_ = -1;
  int num_analyses_ = 0;
  int num_factorizations_ = 0;
  bool factorized_ = false;
};

}  // namespace diffpd::internal
