#include "solver/line_search.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {

int BacktrackingLineSearch(StepObjective& objective, const VectorXd& d, VectorXd* x, double* value,
                           VectorXd* grad) {
  const SolverOptions& options = objective.sim().options;
  const double slope = grad->dot(d);
  if (!(slope < 0)) {
    std::ostringstream msg;
    msg << ToString(options.method) << ": the search direction is not a descent direction (slope " << slope << ")";
    throw SolverError(SolverStatus::kLineSearchFailed, msg.str());
  }
  double alpha = 1.0;
  VectorXd trial_grad;
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
    }
    // Armijo; or, where g's change is lost in rounding (near convergence),
    // a strict decrease of |grad g|.
    const bool moved = (trial - *x).cwiseAbs().maxCoeff() > 0;
    const bool armijo = ok && moved && trial_value < *value && trial_value <= *value + options.armijo_c * alpha * slope;
    const bool rounding = ok && moved && std::abs(trial_value - *value) <= 1e-12 * std::abs(*value) &&
                          trial_grad.norm() < grad->norm();
    if (armijo || rounding) {
      *x = trial;
      *value = trial_value;
      *grad = trial_grad;
      return k;
    }
    alpha *= 0.5;
  }
  std::ostringstream msg;
  msg << ToString(options.method) << ": the line search found no decrease of g after "
      << options.max_line_search_steps << " halvings (|grad g| = " << grad->norm()
      << "; if this is the rounding floor, raise abs_tolerance)";
  throw SolverError(SolverStatus::kLineSearchFailed, msg.str());
}

}  // namespace diffpd::internal
