#include "diffpd/error.h"

#include <cstdio>
#include <cstdlib>

namespace diffpd {

const char* ToString(SolverStatus status) {
  switch (status) {
    case SolverStatus::kConverged:
      return "converged";
    case SolverStatus::kMaxIterations:
      return "maximum number of iterations reached";
    case SolverStatus::kLineSearchFailed:
      return "line search failed";
    case SolverStatus::kNonFinite:
      return "non-finite value";
    case SolverStatus::kFactorizationFailed:
      return "factorization failed";
    case SolverStatus::kInvertedElement:
      return "inverted element";
    case SolverStatus::kDiverged:
      return "diverged";
    case SolverStatus::kActiveSetNotConverged:
      return "contact active set did not converge";
    case SolverStatus::kContactEnergyGain:
      return "contact gained energy";
  }
  return "unknown";
}

namespace internal {
void CheckFailed(const char* file, int line, const char* condition, const std::string& message) {
  std::fprintf(stderr, "DiffPD internal check failed at %s:%d: %s\n  %s\n", file, line, condition, message.c_str());
  std::abort();
}
}  // namespace internal
}  // namespace diffpd
