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

#include <limits>
#include <memory>

#include "diffpd/types.h"
#include "solver/parallel_triangular_solve.h"

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

// Who does the triangular solves. kCholmod: CHOLMOD's own (no copy; for a
// factor solved with once or twice, Newton's). kParallelCopy: a copy of the
// factor made after each factorisation (ParallelTriangularSolve: blocked
// columns, subtrees of the elimination tree on set_solve_threads() threads;
// for a factor solved with at every iteration, PD's). On the cantilever's PD
// factor (2 673 nodes, 217 k entries, 3 right-hand sides) measured about
// CHOLMOD's speed on one thread and 1.2-1.7x faster on two.
enum class CholmodSolveKernel { kCholmod, kParallelCopy };

class CholmodSolver {
 public:
  explicit CholmodSolver(CholmodLayout layout = CholmodLayout::kSupernodal,
                         CholmodOrdering ordering = CholmodOrdering::kAutomatic,
                         CholmodSolveKernel kernel = CholmodSolveKernel::kCholmod);
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

  // kParallelCopy: threads of the solves (>= 1, default 1); takes effect at
  // once (the copy is re-partitioned) or at the next factorisation.
  void set_solve_threads(int threads);
  // kParallelCopy: the most bytes the copy may take (its size estimated from
  // the factor's entries before it is made: ParallelTriangularSolve::
  // EstimatedBytes); above it no copy is made and CHOLMOD solves. >= 0;
  // default: no bound. Takes effect at the next factorisation.
  void set_copy_max_bytes(double bytes) { copy_max_bytes_ = bytes; }
  // kParallelCopy: the copy in use (null before a factorisation, or where the
  // factor was not in the form the copy needs and CHOLMOD solves instead).
  const ParallelTriangularSolve* parallel_copy() const { return copy_.get(); }

  CholmodLayout layout() const { return layout_; }
  int num_analyses() const { return num_analyses_; }
  // Wall seconds of the latest Factorize's symbolic analysis (0 when it
  // reused the previous one).
  double analysis_seconds() const { return analysis_seconds_; }
  // Entries of the factor L after the latest analysis (CHOLMOD's lnz).
  double factor_nonzeros() const;
  // Floating-point operations of one numeric factorisation by the latest
  // analysis (CHOLMOD's fl).
  double factor_flops() const;
  int num_factorizations() const { return num_factorizations_; }
  bool factorized() const { return factorized_; }

 private:
  struct Impl;
  void MakeCopy();

  std::unique_ptr<Impl> impl_;
  CholmodLayout layout_;
  CholmodSolveKernel kernel_;
  int solve_threads_ = 1;
  double copy_max_bytes_ = std::numeric_limits<double>::infinity();
  std::unique_ptr<ParallelTriangularSolve> copy_;
  Eigen::Index rows_ = -1;
  Eigen::Index nonzeros_ = -1;
  int num_analyses_ = 0;
  double analysis_seconds_ = 0;
  int num_factorizations_ = 0;
  bool factorized_ = false;
};

}  // namespace diffpd::internal
