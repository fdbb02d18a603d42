// Error types of the DiffPD library.
//
// Three kinds of failure, three mechanisms:
//  - invalid user input (bad mesh, out-of-range parameter, mismatched sizes):
//    InvalidInputError, whose message names the input, its value and the
//    allowed range;
//  - a numerical solve that does not converge or diverges: SolverError, which
//    carries a SolverStatus the caller can inspect;
//  - a broken internal invariant: DIFFPD_CHECK aborts with a message (it is
//    never compiled out).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace diffpd {

class InvalidInputError : public std::invalid_argument {
 public:
  explicit InvalidInputError(const std::string& message) : std::invalid_argument(message) {}
};

// Why a numerical solve failed.
enum class SolverStatus {
  kConverged = 0,
  kMaxIterations,          // the iteration limit was reached before the tolerance
  kLineSearchFailed,       // no step along the search direction decreased the objective
  kNonFinite,              // a NaN or infinity appeared in the state or a residual
  kFactorizationFailed,    // the (sparse) matrix was not positive definite
  kInvertedElement,        // a material that cannot handle inversion met J <= 0
  kDiverged,               // an iterative linear solve's residual grew or stagnated, or a step
                           // tore the body apart (SolverOptions::max_extent_ratio)
  kActiveSetNotConverged,  // the contact active-set loop did not settle
  kContactEnergyGain       // a step with frictional contact gained energy (contact.h)
};

const char* ToString(SolverStatus status);

class SolverError : public std::runtime_error {
 public:
  SolverError(SolverStatus status, const std::string& message) : std::runtime_error(message), status_(status) {}
  SolverStatus status() const { return status_; }

 private:
  SolverStatus status_;
};

namespace internal {
[[noreturn]] void CheckFailed(const char* file, int line, const char* condition, const std::string& message);
}  // namespace internal

}  // namespace diffpd

// Internal invariant check; always on, aborts with file, line and message.
#define DIFFPD_CHECK(condition, message)                                                           \
  do {                                                                                             \
    if (!(condition)) {                                                                            \
      std::ostringstream diffpd_check_stream_;                                                     \
      diffpd_check_stream_ << message;                                                             \
      ::diffpd::internal::CheckFailed(__FILE__, __LINE__, #condition, diffpd_check_stream_.str()); \
    }                                                                                              \
  } while (false)
