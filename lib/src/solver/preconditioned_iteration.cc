#include "solver/preconditioned_iteration.h"

#include <cmath>
#include <memory>

#include "diffpd/error.h"
#include "solver/lbfgs_pairs.h"

namespace diffpd::internal {
namespace {

enum class ColumnStatus { kRunning, kConverged, kFailed };

// One right-hand side's iteration: the vector to precondition next, and the
// step that consumes A^{-1} of it.
class ColumnIteration {
 public:
  ColumnIteration(const VectorXd& b, double tolerance, const std::function<VectorXd(const VectorXd&)>& apply_h)
      : b_(b), r_(b), z_(VectorXd::Zero(b.size())), tol_(tolerance), apply_h_(apply_h) {}
  virtual ~ColumnIteration() = default;
  virtual const VectorXd& PreconditionerInput() = 0;
  virtual ColumnStatus Advance(const VectorXd& preconditioned) = 0;
  const VectorXd& solution() const { return z_; }

 protected:
  // After r_ was updated by a recurrence: converged when the recurred and a
  // recomputed residual both meet the tolerance (the recomputed one within
  // 10x, against drift); otherwise r_ is replaced by the recomputed one.
  ColumnStatus CheckRecurredResidual() {
    const double rn = r_.norm();
    if (!std::isfinite(rn)) return ColumnStatus::kFailed;
    if (rn > tol_) return ColumnStatus::kRunning;
    r_ = b_ - apply_h_(z_);
    return r_.norm() <= 10 * tol_ ? ColumnStatus::kConverged : ColumnStatus::kRunning;
  }

  const VectorXd b_;
  VectorXd r_;  // b - H z
  VectorXd z_;
  const double tol_;
  const std::function<VectorXd(const VectorXd&)>& apply_h_;
};

class FixedPointColumn final : public ColumnIteration {
 public:
  using ColumnIteration::ColumnIteration;
  const VectorXd& PreconditionerInput() override { return r_; }
  ColumnStatus Advance(const VectorXd& d) override {
    z_ += d;
    r_ = b_ - apply_h_(z_);
    const double rn = r_.norm();
    if (!std::isfinite(rn) || rn > 10 * best_) return ColumnStatus::kFailed;  // growth
    if (rn <= tol_) return ColumnStatus::kConverged;
    if (rn < 0.999 * best_) {
      best_ = rn;
      stalled_ = 0;
    } else if (++stalled_ >= 20) {
      return ColumnStatus::kFailed;  // stagnation
    }
    return ColumnStatus::kRunning;
  }

 private:
  double best_ = b_.norm();
  int stalled_ = 0;
};

class LbfgsColumn final : public ColumnIteration {
 public:
  LbfgsColumn(const VectorXd& b, double tolerance, const std::function<VectorXd(const VectorXd&)>& apply_h, int history)
      : ColumnIteration(b, tolerance, apply_h), pairs_(history, b.size()) {}

  // First loop of the two-loop recursion on the gradient -r.
  const VectorXd& PreconditionerInput() override {
    q_ = -r_;
    pairs_.FirstLoop(&q_, &alpha_);
    return q_;
  }

  ColumnStatus Advance(const VectorXd& preconditioned) override {
    VectorXd p = preconditioned;
    pairs_.SecondLoop(alpha_, &p);
    p = -p;
    const VectorXd hp = apply_h_(p);
    const double curvature = p.dot(hp);
    if (!(curvature > 0)) return ColumnStatus::kFailed;  // H is not positive definite
    const double step = r_.dot(p) / curvature;
    z_ += step * p;
    r_ -= step * hp;
    const ColumnStatus status = CheckRecurredResidual();
    pairs_.Push(step * p, step * hp, 1.0 / (step * step * curvature));
    return status;
  }

 private:
  LbfgsPairs pairs_;
  std::vector<double> alpha_;
  VectorXd q_;
};

class ConjugateGradientColumn final : public ColumnIteration {
 public:
  using ColumnIteration::ColumnIteration;
  const VectorXd& PreconditionerInput() override { return r_; }
  ColumnStatus Advance(const VectorXd& s) override {
    const double rs = r_.dot(s);
    if (p_.size() == 0)
      p_ = s;
    else
      p_ = s + (rs / rs_) * p_;
    rs_ = rs;
    const VectorXd hp = apply_h_(p_);
    const double curvature = p_.dot(hp);
    if (!(curvature > 0)) return ColumnStatus::kFailed;  // H is not positive definite
    const double step = rs / curvature;
    z_ += step * p_;
    r_ -= step * hp;
    return CheckRecurredResidual();
  }

 private:
  VectorXd p_;
  double rs_ = 0;
};

// tolerance: the absolute residual norm to reach.
std::unique_ptr<ColumnIteration> MakeColumn(const PreconditionedSolveOptions& options, const VectorXd& b,
                                            double tolerance, const std::function<VectorXd(const VectorXd&)>& apply_h) {
  switch (options.method) {
    case PdBackwardMethod::kFixedPoint:
      return std::make_unique<FixedPointColumn>(b, tolerance, apply_h);
    case PdBackwardMethod::kLbfgs:
      return std::make_unique<LbfgsColumn>(b, tolerance, apply_h, options.lbfgs_history);
    case PdBackwardMethod::kConjugateGradient:
      break;
  }
  return std::make_unique<ConjugateGradientColumn>(b, tolerance, apply_h);
}

}  // namespace

void SolvePreconditioned(const PreconditionedSolveOptions& options, const MatrixXd& b,
                         const std::function<VectorXd(const VectorXd&)>& apply_h,
                         const std::function<MatrixXd(const MatrixXd&)>& precondition, MatrixXd* z,
                         std::vector<char>* ok, int* iterations) {
  const int cols = static_cast<int>(b.cols());
  *z = MatrixXd::Zero(b.rows(), cols);
  ok->assign(cols, 0);
  std::vector<std::unique_ptr<ColumnIteration>> column(cols);
  std::vector<int> active;
  const bool given = options.reference_norms.size() > 0;
  DIFFPD_CHECK(
      !given || options.reference_norms.size() == cols,
      "SolvePreconditioned: " << options.reference_norms.size() << " reference norms for " << cols << " columns");
  for (int c = 0; c < cols; ++c) {
    const double norm = b.col(c).norm();
    const double tolerance = options.rel_tolerance * (given ? options.reference_norms(c) : norm);
    if (norm == 0 || (given && norm <= tolerance)) {
      (*ok)[c] = 1;
      continue;
    }
    column[c] = MakeColumn(options, b.col(c), tolerance, apply_h);
    active.push_back(c);
  }
  for (int it = 1; it <= options.max_iterations && !active.empty(); ++it) {
    const int na = static_cast<int>(active.size());
    MatrixXd input(b.rows(), na);
    for (int j = 0; j < na; ++j) input.col(j) = column[active[j]]->PreconditionerInput();
    const MatrixXd preconditioned = precondition(input);
    *iterations += na;
    std::vector<int> still;
    for (int j = 0; j < na; ++j) {
      const int c = active[j];
      const ColumnStatus status = column[c]->Advance(preconditioned.col(j));
      if (status == ColumnStatus::kConverged)
        (*ok)[c] = 1;
      else if (status == ColumnStatus::kRunning)
        still.push_back(c);
    }
    active.swap(still);
  }
  for (int c = 0; c < cols; ++c)
    if ((*ok)[c] && column[c]) z->col(c) = column[c]->solution();
}

}  // namespace diffpd::internal
