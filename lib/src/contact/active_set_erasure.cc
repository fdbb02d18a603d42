#include "contact/active_set_erasure.h"

#include <algorithm>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {

ActiveSetErasure::ActiveSetErasure() = default;
ActiveSetErasure::~ActiveSetErasure() = default;
ActiveSetErasure::ActiveSetErasure(ActiveSetErasure&&) noexcept = default;
ActiveSetErasure& ActiveSetErasure::operator=(ActiveSetErasure&&) noexcept = default;

void ActiveSetErasure::Reset() {
  nodes_.clear();
  prepared_ = false;
  active_ = false;
  columns_.clear();
  w_.resize(0, 0);
}

void ActiveSetErasure::Set(const std::vector<int>& nodes, ContactLinearSolve mode, const SparseMatrix& matrix,
                           const CholmodSolver& base, const std::vector<char>& base_fixed) {
  std::vector<int> erased;
  for (const int i : nodes)
    if (!base_fixed[i]) erased.push_back(i);
  active_ = !erased.empty();
  if (!active_ || (prepared_ && erased == nodes_ && mode == mode_)) return;
  prepared_ = false;
  nodes_ = std::move(erased);
  mode_ = mode;
  const int n = static_cast<int>(matrix.rows());
  const int s = static_cast<int>(nodes_.size());
  if (mode == ContactLinearSolve::kRefactorize) {
    std::vector<char> drop(n, 0);
    for (const int i : nodes_) drop[i] = 1;
    SparseMatrix a = matrix;
    double* values = a.valuePtr();
    const int* rows = a.innerIndexPtr();
    for (int col = 0; col < n; ++col)
      for (int t = a.outerIndexPtr()[col]; t < a.outerIndexPtr()[col + 1]; ++t)
        if (drop[col] || drop[rows[t]]) values[t] = rows[t] == col ? 1.0 : 0.0;
    if (!erased_solver_) erased_solver_ = std::make_unique<CholmodSolver>();
    ++num_factorizations_;
    if (!erased_solver_->Factorize(a)) {
      active_ = false;
      throw SolverError(SolverStatus::kFactorizationFailed,
                        "frictional contact: the PD matrix with the active set erased is not positive definite");
    }
    prepared_ = true;
    return;
  }
  // Woodbury: the missing columns of W in one multi-RHS solve.
  std::vector<int> missing;
  for (const int i : nodes_)
    if (!columns_.count(i)) missing.push_back(i);
  if (!missing.empty()) {
    MatrixXd unit = MatrixXd::Zero(n, static_cast<Eigen::Index>(missing.size()));
    for (size_t c = 0; c < missing.size(); ++c) unit(missing[c], static_cast<Eigen::Index>(c)) = 1.0;
    const MatrixXd cols = base.Solve(unit);
    num_column_solves_ += static_cast<int>(missing.size());
    for (size_t c = 0; c < missing.size(); ++c) columns_[missing[c]] = cols.col(static_cast<Eigen::Index>(c));
  }
  // Bound the cache: columns of nodes that left the set stay (a node that
  // comes back costs nothing) until they outnumber the set plus
  // kCacheSlack; then all of them go (re-solved if they return).
  if (columns_.size() > 2 * nodes_.size() + kCacheSlack) {
    for (auto it = columns_.begin(); it != columns_.end();) {
      if (std::binary_search(nodes_.begin(), nodes_.end(), it->first))
        ++it;
      else
        it = columns_.erase(it);
    }
  }
  MatrixXd cap(s, s);
  for (int c = 0; c < s; ++c) {
    const VectorXd& column = columns_.at(nodes_[c]);
    for (int r = 0; r < s; ++r) cap(r, c) = column(nodes_[r]);
  }
  if (s <= kDenseCorrectionMax) {
    w_.resize(n, s);
    for (int c = 0; c < s; ++c) w_.col(c) = columns_.at(nodes_[c]);
  } else {
    w_.resize(0, 0);
  }
  capacitance_.compute(0.5 * (cap + cap.transpose()));
  if (capacitance_.info() != Eigen::Success) {
    active_ = false;
    std::ostringstream msg;
    msg << "frictional contact: the Woodbury capacitance matrix of " << s << " active nodes is not positive definite";
    throw SolverError(SolverStatus::kFactorizationFailed, msg.str());
  }
  prepared_ = true;
}

void ActiveSetErasure::ZeroErased(MatrixXd* x) const {
  for (const int i : nodes_) x->row(i).setZero();
}

MatrixXd ActiveSetErasure::Solve(const CholmodSolver& base, MatrixXd rhs) const {
  ZeroErased(&rhs);
  if (mode_ == ContactLinearSolve::kRefactorize) {
    MatrixXd y = erased_solver_->Solve(rhs);
    ZeroErased(&y);
    return y;
  }
  MatrixXd y = base.Solve(rhs);
  const int s = static_cast<int>(nodes_.size());
  MatrixXd ys(s, y.cols());
  for (int r = 0; r < s; ++r) ys.row(r) = y.row(nodes_[r]);
  const MatrixXd lambda = capacitance_.solve(ys);
  if (s <= kDenseCorrectionMax) {
    // Column by column: matrix-vector products (a matrix product would pack
    // W for a few right-hand sides, measured as costly as the rest of the solve).
    for (Eigen::Index c = 0; c < y.cols(); ++c) y.col(c).noalias() -= w_ * lambda.col(c);
  } else {
    // A^-1 (R - P lambda): R is zero on S, so the corrected right-hand side
    // is -lambda there and R elsewhere.
    for (int r = 0; r < s; ++r) rhs.row(nodes_[r]) = -lambda.row(r);
    y = base.Solve(rhs);
  }
  ZeroErased(&y);
  return y;
}

}  // namespace diffpd::internal
