#include "solver/cholmod_solver.h"

#include <omp.h>

#include <chrono>
#include <vector>

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

// Eigen's CHOLMOD wrapper with its factor readable (a protected member).
template <class Base>
class ReadableFactor : public Base {
 public:
  const cholmod_factor* factor() const { return this->m_cholmodFactor; }
};

// Column j of a CHOLMOD LL^T factor, simplicial or supernodal.
ParallelTriangularSolve::Column FactorColumn(const cholmod_factor& f, const std::vector<int>& node_of_column, int j) {
  if (!f.is_super) {
    const int p = static_cast<const int*>(f.p)[j];
    return {static_cast<const int*>(f.i) + p, static_cast<const double*>(f.x) + p, static_cast<const int*>(f.nz)[j]};
  }
  const int s = node_of_column[j];
  const int first = static_cast<const int*>(f.super)[s];
  const int row_begin = static_cast<const int*>(f.pi)[s], row_end = static_cast<const int*>(f.pi)[s + 1];
  const int nrow = row_end - row_begin, c = j - first;
  const long values = static_cast<const int*>(f.px)[s] + static_cast<long>(c) * nrow + c;
  return {static_cast<const int*>(f.s) + row_begin + c, static_cast<const double*>(f.x) + values, nrow - c};
}

}  // namespace

struct CholmodSolver::Impl {
  // Exactly one is used, by layout_ (Eigen gives each layout its own type).
  ReadableFactor<Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower>> supernodal;
  ReadableFactor<Eigen::CholmodSimplicialLLT<SparseMatrix, Eigen::Lower>> simplicial;

  template <class Body>
  auto With(CholmodLayout layout, Body&& body) {
    return layout == CholmodLayout::kSupernodal ? body(supernodal) : body(simplicial);
  }
};

CholmodSolver::CholmodSolver(CholmodLayout layout, CholmodOrdering ordering, CholmodSolveKernel kernel)
    : impl_(std::make_unique<Impl>()), layout_(layout), kernel_(kernel) {
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
  analysis_seconds_ = 0;
  factorized_ = impl_->With(layout_, [&](auto& llt) {
    if (analyse) {
      const auto start = std::chrono::steady_clock::now();
      llt.analyzePattern(a);
      analysis_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    llt.factorize(a);
    return llt.info() == Eigen::Success;
  });
  ++num_factorizations_;
  copy_.reset();
  if (factorized_ && kernel_ == CholmodSolveKernel::kParallelCopy) MakeCopy();
  return factorized_;
}

void CholmodSolver::MakeCopy() {
  const cholmod_factor* f = impl_->With(layout_, [](auto& llt) { return llt.factor(); });
  if (f == nullptr || !f->is_ll || f->xtype != CHOLMOD_REAL || f->itype != CHOLMOD_INT) return;
  const int n = static_cast<int>(f->n);
  // The lean path: CHOLMOD solves.
  if (ParallelTriangularSolve::EstimatedBytes(n, factor_nonzeros()) > copy_max_bytes_) return;
  std::vector<int> node_of_column;
  if (f->is_super) {
    node_of_column.resize(n);
    const int* super = static_cast<const int*>(f->super);
    for (size_t s = 0; s < f->nsuper; ++s)
      for (int j = super[s]; j < super[s + 1]; ++j) node_of_column[j] = static_cast<int>(s);
  }
  copy_ = ParallelTriangularSolve::Create(
      n, static_cast<const int*>(f->Perm), [&](int j) { return FactorColumn(*f, node_of_column, j); }, solve_threads_);
}

void CholmodSolver::set_solve_threads(int threads) {
  DIFFPD_CHECK(threads >= 1, "CholmodSolver: " << threads << " solve threads");
  if (threads == solve_threads_) return;
  solve_threads_ = threads;
  if (copy_) MakeCopy();
}

double CholmodSolver::factor_nonzeros() const {
  return impl_->With(layout_, [](auto& llt) { return llt.cholmod().lnz; });
}

double CholmodSolver::factor_flops() const {
  return impl_->With(layout_, [](auto& llt) { return llt.cholmod().fl; });
}

MatrixXd CholmodSolver::Solve(const MatrixXd& b) const {
  DIFFPD_CHECK(factorized_, "CholmodSolver::Solve before a successful Factorize");
  if (copy_) {
    DIFFPD_CHECK(b.rows() == rows_, "CholmodSolver::Solve: " << b.rows() << " rows for " << rows_);
    MatrixXd x(b.rows(), b.cols());
    copy_->Solve(b.data(), x.data(), static_cast<int>(b.cols()));
    return x;
  }
  return impl_->With(layout_, [&](auto& llt) -> MatrixXd { return llt.solve(b); });
}

VectorXd CholmodSolver::Solve(const VectorXd& b) const {
  DIFFPD_CHECK(factorized_, "CholmodSolver::Solve before a successful Factorize");
  if (copy_) {
    DIFFPD_CHECK(b.rows() == rows_, "CholmodSolver::Solve: " << b.rows() << " rows for " << rows_);
    VectorXd x(b.rows());
    copy_->Solve(b.data(), x.data(), 1);
    return x;
  }
  return impl_->With(layout_, [&](auto& llt) -> VectorXd { return llt.solve(b); });
}

}  // namespace diffpd::internal
