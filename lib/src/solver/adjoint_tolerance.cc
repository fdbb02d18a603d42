#include "solver/adjoint_tolerance.h"

#include <algorithm>

namespace diffpd::internal {

double AdjointRelTolerance(const SolverOptions& options, double forward_rel_tolerance, const StepReport* forward) {
  if (options.backward_rel_tolerance > 0) return options.backward_rel_tolerance;
  double reached = forward_rel_tolerance;
  if (forward && forward->initial_residual > 0) {
    reached = forward->final_residual / forward->initial_residual;
    if (forward_rel_tolerance > 0) reached = std::min(reached, forward_rel_tolerance);
  }
  return std::max(options.backward_tolerance_factor * std::min(reached, 1.0), kMinAdjointRelTolerance);
}

}  // namespace diffpd::internal
