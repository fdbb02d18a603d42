#include "solver/cholmod_solver.h"

#include <Eigen/CholmodSupport>

#include "diffpd/error.h"

namespace diffpd::internal {

struct CholmodSolver::Impl {
  // Exactly one is used, by layout_ (Eigen gives each layout its own type).
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> supernodal;
  Eigen::CholmodSimplicialLLT<SparseMatrix, Eigen::Lower> simplicial;

  template <class Body>
  auto With(CholmodLayout layout, Body&& body) {
    return layout == CholmodLayout::kSupernodal ? body(supernodal) : body(simplicial);
  }
};

CholmodSolver::CholmodSolver(CholmodLayout layout) : impl_(std::make_unique<Impl>()), layout_(layout) {
  // Failures are reported through return values.
  impl_->supernodal.cholmod().print = 0;
  impl_->simplicial.cholmod().print = 0;
}

CholmodSolver::~CholmodSolver() = default;

bool CholmodSolver::Factorize(const SparseMatrix& a) {
  DIFFPD_CHECK(a.rows() == a.cols(), "CholmodSolver needs a square matrix");
  const bool analyse = a.rows() != rows_ || a.nonZeros() != nonzeros_;
  if (analyse) {
    rows_ = a.rows();
    nonzeros_ = a.nonZeros();
    ++num_analyses_;
  }
  factorized_ = impl_->With(layout_, [&](auto& llt) {
    if (analyse) llt.analyzePattern(a);
    llt.factorize(a);
    return llt.info() == Eigen::Success;
  });
  ++num_factorizations_;
  return factorized_;
}

MatrixXd CholmodSolver::Solve(const MatrixXd& b) const {
  DIFFPD_CHECK(factorized_, "CholmodSolver::Solve before a successful Factorize");
  return impl_->With(layout_, [&](auto& llt) -> MatrixXd { return llt.solve(b); });
}

VectorXd CholmodSolver::Solve(const VectorXd& b) const {
  DIFFPD_CHECK(factorized_, "CholmodSolver::Solve before a successful Factorize");
  return impl_->With(layout_, [&](auto& llt) -> VectorXd { return llt.solve(b); });
}

}  // namespace diffpd::internal
