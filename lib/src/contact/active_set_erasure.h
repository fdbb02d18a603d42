// Solves with a prefactorised SPD matrix whose rows and columns of a node set
// S (the contact active set) are erased, without refactorising (internal).
//
// A is n x n (one PD axis group; its Dirichlet rows are already the
// identity's). A_S is A with the rows and columns of S replaced by the
// identity's. For R with R_S = 0 (entries of S are ignored) the solution of
// A_S Y = R with Y_S = 0 is, by the Sherman-Morrison-Woodbury identity on the
// bordered system [A P; P^T 0],
//
//   Y = A^-1 R - W C^-1 (A^-1 R)_S,   W = A^-1 P (n x s),  C = P^T A^-1 P = W_S,
//
// P the n x s selection of S. Cost: s solves with A's factor for the columns
// of W (cached per node until the factor changes, so a node that stays in
// contact over many steps costs one solve in all; the cache is bounded, see
// kCacheSlack), a dense s x s Cholesky per
// change of S, and per solve one solve with A plus O(n s). For s above
// kDenseCorrectionMax the O(n s) product W C^-1 (A^-1 R)_S (memory-bound, it
// reads all of W) costs about as much as a second solve with A (measured on a
// 3125-node slab: equal near s = 150), so the correction is applied as
// Y = A^-1 (R - P C^-1 (A^-1 R)_S) instead (same Y; W is then never
// assembled, only C from the cached columns). kRefactorize
// instead factorises A_S (for comparison; same solution). Either way the
// prepared set is kept while erasure is switched off (empty Set), so setting
// the same S again (the next step of a resting contact) costs nothing.
#pragma once

#include <memory>
#include <unordered_map>
#include <vector>

#include <Eigen/Cholesky>

#include "diffpd/contact.h"
#include "diffpd/types.h"
#include "solver/cholmod_solver.h"

namespace diffpd::internal {

class ActiveSetErasure {
 public:
  // Largest active set whose Woodbury correction is the dense product with W
  // (above: a second solve with A; see the comment at the top).
  static constexpr int kDenseCorrectionMax = 128;
  // Cached columns beyond the current set's own: at most |S| + kCacheSlack
  // (memory O((2 |S| + kCacheSlack) n) however many nodes ever touched).
  static constexpr int kCacheSlack = 64;

  ActiveSetErasure();
  ~ActiveSetErasure();
  ActiveSetErasure(ActiveSetErasure&&) noexcept;
  ActiveSetErasure& operator=(ActiveSetErasure&&) noexcept;

  // Erases `nodes` (sorted, unique); those already fixed in `base_fixed` (n
  // flags) are skipped. `matrix` is A and `base` its current factor.
  // Throws SolverError(kFactorizationFailed) if C or A_S is not positive definite.
  void Set(const std::vector<int>& nodes, ContactLinearSolve mode, const SparseMatrix& matrix,
           const CholmodSolver& base, const std::vector<char>& base_fixed);
  // The base factor changed: drops the cached columns and the erased set
  // (call Set again).
  void Reset();
  bool empty() const { return !active_; }

  // Solves A_S Y = R (n x k): rows of R at S are ignored, rows of Y at S are
  // zero. Rows of R at the base's fixed nodes must already be zero.
  MatrixXd Solve(const CholmodSolver& base, MatrixXd rhs) const;
  // Rows of S of x set to zero (the erasure of A_S x's columns and rows).
  void ZeroErased(MatrixXd* x) const;

  int num_column_solves() const { return num_column_solves_; }
  int num_cached_columns() const { return static_cast<int>(columns_.size()); }
  int num_factorizations() const { return num_factorizations_; }

 private:
  std::vector<int> nodes_;  // the prepared set
  bool prepared_ = false;   // nodes_ is prepared for the current factor
  bool active_ = false;     // erasure on (a non-empty set is set)
  ContactLinearSolve mode_ = ContactLinearSolve::kWoodbury;
  std::unordered_map<int, VectorXd> columns_;  // node -> A^-1 e_node
  MatrixXd w_;                                 // n x s (s <= kDenseCorrectionMax), else empty
  Eigen::LLT<MatrixXd> capacitance_;           // of C = W_S
  std::unique_ptr<CholmodSolver> erased_solver_;
  int num_column_solves_ = 0;
  int num_factorizations_ = 0;
};

}  // namespace diffpd::internal
