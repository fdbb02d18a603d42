#include "solver/cholmod_solver.h"

#include <omp.h>

#include <Eigen/CholmodSupport>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

// For its lifetime, OpenMP parallel regions run on the calling thread alone.
// CHOLMOD's supernodal factorisation opens its parallel loops with a fixed
// team of CHOLMOD_OMP_NUM_THREADS = 4 threads (a compile-time constant of the
// Debian build, not capped by OMP_NUM_THREADS or the caller's thread count):
// on the 2-core machines this project targets the oversubscribed team spent
// ~20% of a Newton run in the kernel (futex waits, context switches) and made
// Newton-Cholesky 1.7x slower on the rolling sphere, 1 or 2 threads alike.
class SerialOpenMpScope {
 public:
  SerialOpenMpScope() : saved_(omp_get_max_active_levels()) { omp_set_max_active_levels(0); }
  ~SerialOpenMpScope() { omp_set_max_active_levels(saved_); }
  SerialOpenMpScope(const SerialOpenMpScope&) = delete;
  SerialOpenMpScope& operator=(const SerialOpenMpScope&) = delete;

 private:
  int saved_;
};

}  // namespace

struct CholmodSolver::Impl {
  // Exactly one is used, by layout_ (Eigen gives each layout its own type).
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> supernodal;
  Eigen::CholmodSimplicialLLT<SparseMatrix, Eigen::Lower> simplicial;

  template <class Body>
  auto With(CholmodLayout layout, Body&& body) {
    return layout == CholmodLayout::kSupernodal ? body(supernodal) : body(simplicial);
  }
};

CholmodSolver::CholmodSolver(CholmodLayout layout, CholmodOrdering ordering)
    : impl_(std::make_unique<Impl>()), layout_(layout) {
  for (cholmod_common* common : {&impl_->supernodal.cholmod(), &impl_->simplicial.cholmod()}) {
    common->print = 0;  // failures are reported through return values
    if (ordering == CholmodOrdering::kNestedDissection) {
      common->nmethods = 1;
      common->method[0].ordering = CHOLMOD_NESDIS;
    }
  }
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
  const SerialOpenMpScope serial;
  factorized_ = impl_->With(layout_, [&](auto& llt) {
    if (analyse) llt.analyzePattern(a);
    llt.factorize(a);
    return llt.info() == Eigen::Success;
  });
  ++num_factorizations_;
  return factorized_;
}

double CholmodSolver::factor_nonzeros() const {
  return impl_->With(layout_, [](auto& llt) { return llt.cholmod().lnz; });
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
