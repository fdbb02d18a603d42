#include "solver/line_search.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {
// A change of g below this fraction of |g| is rounding.
constexpr double kRoundingRelative = 1e-12;
// Where the predicted decrease -grad^T d is below this fraction of |g|, g
// cannot tell a decrease from rounding (changes up to the same bound).
constexpr double kBlindRelative = 1e-10;
}  // namespace

LineSearchResult BacktrackingLineSearch(StepObjective& objective, const VectorXd& d, VectorXd* x, double* value,
                                        VectorXd* grad) {
  const SolverOptions& options = objective.sim().options;
  const double slope = grad->dot(d);
  if (!std::isfinite(slope)) {
    std::ostringstream msg;
    msg << ToString(options.method) << ": the line search's slope grad g . d = " << slope
        << " is not finite (|grad g| = " << grad->norm() << ", |d| = " << d.norm() << ")";
    throw SolverError(SolverStatus::kNonFinite, msg.str());
  }
  if (!(slope < 0)) {
    std::ostringstream msg;
    msg << ToString(options.method) << ": the search direction is not a descent direction (slope " << slope << ")";
    throw SolverError(SolverStatus::kLineSearchFailed, msg.str());
  }
  double alpha = 1.0;
  VectorXd trial_grad;
  bool every_trial_overflowed = true;  // g or grad g was not finite at every trial point
  for (int k = 0; k <= options.max_line_search_steps; ++k) {
    const VectorXd trial = *x + alpha * d;
    double trial_value = 0;
    bool ok = true;
    try {
      trial_value = objective.Evaluate(trial, &trial_grad);
    } catch (const SolverError& e) {
      // Non-finite or inverted trial points are rejected like too-long steps.
      if (e.status() != SolverStatus::kNonFinite && e.status() != SolverStatus::kInvertedElement) throw;
      ok = false;
      every_trial_overflowed = every_trial_overflowed && e.status() == SolverStatus::kNonFinite;
    }
    if (ok) every_trial_overflowed = false;
    // Armijo; or, where g's change is lost in rounding (near convergence),
    // a strict decrease of |grad g|. g's rounding is relative to its terms,
    // which can be far larger than g itself (the elastic energy near rest is
    // a sum of squares of sigma - 1, each with the absolute rounding of
    // sigma): where the predicted decrease is below kBlindRelative of g, a
    // change of g within that bound is rounding, not an increase.
    const bool moved = (trial - *x).cwiseAbs().maxCoeff() > 0;
    const bool armijo = ok && moved && trial_value < *value && trial_value <= *value + options.armijo_c * alpha * slope;
    const double change = std::abs(trial_value - *value), scale = std::abs(*value);
    const bool blind = change <= kRoundingRelative * scale ||
                       (std::abs(slope) <= kBlindRelative * scale && change <= kBlindRelative * scale);
    const bool rounding = ok && moved && blind && trial_grad.norm() < grad->norm();
    if (armijo || rounding) {
      *x = trial;
      *value = trial_value;
      *grad = trial_grad;
      return LineSearchResult{k, false};
    }
    alpha *= 0.5;
  }
  if (every_trial_overflowed) {
    std::ostringstream msg;
    msg << ToString(options.method) << ": g is not finite at any line search point x + d / 2^k, k = 0.."
        << options.max_line_search_steps << " (|grad g| = " << grad->norm() << ", |d| = " << d.norm()
        << "): the step's forces or stiffness overflow double precision";
    throw SolverError(SolverStatus::kNonFinite, msg.str());
  }
  const double floor = objective.RoundingFloor();
  if (options.accept_rounding_floor && grad->norm() <= StepObjective::kRoundingFloorStall * floor)
    return LineSearchResult{options.max_line_search_steps, true};
  std::ostringstream msg;
  msg << ToString(options.method) << ": the line search found no decrease of g after " << options.max_line_search_steps
      << " halvings (|grad g| = " << grad->norm() << ", estimated rounding floor " << floor << ")";
  throw SolverError(SolverStatus::kLineSearchFailed, msg.str());
}

}  // namespace diffpd::internal
