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

class CholmodSolver {
 public:
  explicit CholmodSolver(CholmodLayout layout = CholmodLayout::kSupernodal);
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
