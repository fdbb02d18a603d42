#include "solver/hessian_factorization.h"

#include <chrono>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

HessianFactorization::HessianFactorization(HessianFactorizationKind kind) : kind_(kind) {
  if (kind == HessianFactorizationKind::kCholmodSupernodal)
    cholmod_ = std::make_unique<CholmodSolver>(CholmodLayout::kSupernodal);
  else
    ldlt_ = std::make_unique<Eigen::SimplicialLDLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>>>();
}

int HessianFactorization::num_analyses() const { return cholmod_ ? cholmod_->num_analyses() : num_ldlt_analyses_; }

double HessianFactorization::factor_nonzeros() const {
  return cholmod_ && cholmod_->num_analyses() > 0 ? cholmod_->factor_nonzeros() : 0.0;
}

double HessianFactorization::factor_flops() const {
  return cholmod_ && cholmod_->num_analyses() > 0 ? cholmod_->factor_flops() : 0.0;
}

bool HessianFactorization::Factorize(const SparseMatrix& h) {
  DIFFPD_CHECK(h.rows() == h.cols(), "HessianFactorization needs a square matrix");
  const auto start = Clock::now();
  ++num_factorizations_;
  if (cholmod_) {
    factorized_ = cholmod_->Factorize(h);
    factorize_seconds_ = Since(start);
    analysis_seconds_ = cholmod_->analysis_seconds();
    return factorized_;
  }
  ldlt_->analyzePattern(h);
  ++num_ldlt_analyses_;
  analysis_seconds_ = Since(start);
  ldlt_->factorize(h);
  factorized_ = ldlt_->info() == Eigen::Success;
  factorize_seconds_ = Since(start);
  return factorized_;
}

VectorXd HessianFactorization::Solve(const VectorXd& b) const {
  DIFFPD_CHECK(factorized_, "HessianFactorization::Solve before a successful Factorize");
  if (cholmod_) return cholmod_->Solve(b);
  return ldlt_->solve(b);
}

MatrixXd HessianFactorization::Solve(const MatrixXd& b) const {
  DIFFPD_CHECK(factorized_, "HessianFactorization::Solve before a successful Factorize");
  if (cholmod_) return cholmod_->Solve(b);
  return ldlt_->solve(b);
}

}  // namespace diffpd::internal
