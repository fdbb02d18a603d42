#include "solver/cholmod_solver.h"

#include <Eigen/CholmodSupport>

#include "diffpd/error.h"

namespace diffpd::internal {

struct CholmodSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt;
};

CholmodSolver::CholmodSolver() : impl_(std::make_unique<Impl>()) {
  impl_->llt.cholmod().print = 0;  // failures are reported through return values
}

CholmodSolver::~CholmodSolver() = default;

bool CholmodSolver::Factorize(const SparseMatrix& a) {
  DIFFPD_CHECK(a.rows() == a.cols(), "CholmodSolver needs a square matrix");
  if (a.rows() != rows_ || a.nonZeros() != nonzeros_) {
    impl_->llt.analyzePattern(a);
    rows_ = a.rows();
    nonzeros_ = a.nonZeros();
    ++num_analyses_;
  }
  impl_->llt.factorize(a);
  ++num_factorizations_;
  factorized_ = impl_->llt.info() == Eigen::Success;
  return factorized_;
}

MatrixXd CholmodSolver::Solve(const MatrixXd& b) const {
  DIFFPD_CHECK(factorized_, "CholmodSolver::Solve before a successful Factorize");
  return impl_->llt.solve(b);
}

VectorXd CholmodSolver::Solve(const VectorXd& b) const {
  DIFFPD_CHECK(factorized_, "CholmodSolver::Solve before a successful Factorize");
  return impl_->llt.solve(b);
}

}  // namespace diffpd::internal
