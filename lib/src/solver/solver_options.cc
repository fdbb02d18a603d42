#include "diffpd/solver_options.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd {
namespace {
constexpr Method kMethods[] = {Method::kSemiImplicit, Method::kNewtonCholesky, Method::kNewtonPcg,
                               Method::kPd,           Method::kPdLbfgs,        Method::kNewtonLdlt};
constexpr AdjointSolver kAdjointSolvers[] = {AdjointSolver::kAuto, AdjointSolver::kIterative, AdjointSolver::kDirect};

template <class T>
[[noreturn]] void Reject(const char* field, T value, const char* range) {
  std::ostringstream msg;
  msg << "solver options: " << field << " = " << value << " is invalid: must be " << range;
  throw InvalidInputError(msg.str());
}
}  // namespace

const char* ToString(Method method) {
  switch (method) {
    case Method::kSemiImplicit:
      return "semi-implicit";
    case Method::kNewtonCholesky:
      return "newton-cholesky";
    case Method::kNewtonPcg:
      return "newton-pcg";
    case Method::kPd:
      return "pd";
    case Method::kPdLbfgs:
      return "pd-lbfgs";
    case Method::kNewtonLdlt:
      return "newton-ldlt";
  }
  return "unknown";
}

const char* ToString(AdjointSolver solver) {
  switch (solver) {
    case AdjointSolver::kAuto:
      return "auto";
    case AdjointSolver::kIterative:
      return "iterative";
    case AdjointSolver::kDirect:
      return "direct";
  }
  return "unknown";
}

AdjointSolver ParseAdjointSolver(const std::string& name) {
  std::string valid;
  for (const AdjointSolver a : kAdjointSolvers) {
    if (name == ToString(a)) return a;
    valid += valid.empty() ? "" : ", ";
    valid += ToString(a);
  }
  throw InvalidInputError("unknown adjoint solver '" + name + "': valid adjoint solvers are " + valid);
}

Method ParseMethod(const std::string& name) {
  std::string valid;
  for (const Method m : kMethods) {
    if (name == ToString(m)) return m;
    valid += valid.empty() ? "" : ", ";
    valid += ToString(m);
  }
  throw InvalidInputError("unknown method '" + name + "': valid methods are " + valid);
}

int MaxSolverThreads() { return 4 * omp_get_num_procs(); }

void SolverOptions::Validate() const {
  if (std::find(std::begin(kMethods), std::end(kMethods), method) == std::end(kMethods))
    Reject("method", static_cast<int>(method),
           "a Method: semi-implicit (0), newton-cholesky (1), newton-pcg (2), pd (3), pd-lbfgs (4) or newton-ldlt (5)");
  if (pcg_preconditioner != PcgPreconditioner::kJacobi && pcg_preconditioner != PcgPreconditioner::kIncompleteCholesky)
    Reject("pcg_preconditioner", static_cast<int>(pcg_preconditioner), "kJacobi (0) or kIncompleteCholesky (1)");
  if (pd_backward != PdBackwardMethod::kFixedPoint && pd_backward != PdBackwardMethod::kLbfgs &&
      pd_backward != PdBackwardMethod::kConjugateGradient)
    Reject("pd_backward", static_cast<int>(pd_backward), "kFixedPoint (0), kLbfgs (1) or kConjugateGradient (2)");
  if (!(std::isfinite(time_step) && time_step > 0)) Reject("time_step", time_step, "finite and > 0 (s)");
  if (!(std::isfinite(abs_tolerance) && abs_tolerance >= 0)) Reject("abs_tolerance", abs_tolerance, "finite and >= 0");
  if (!(std::isfinite(rel_tolerance) && rel_tolerance >= 0 && rel_tolerance < 1))
    Reject("rel_tolerance", rel_tolerance, "in [0, 1)");
  if (abs_tolerance == 0 && rel_tolerance == 0)
    throw InvalidInputError("solver options: abs_tolerance and rel_tolerance are both 0; at least one must be > 0");
  if (max_iterations < 1) Reject("max_iterations", max_iterations, ">= 1");
  if (!(armijo_c > 0 && armijo_c < 1)) Reject("armijo_c", armijo_c, "in (0, 1)");
  if (max_line_search_steps < 1) Reject("max_line_search_steps", max_line_search_steps, ">= 1");
  if (!(pcg_rel_tolerance > 0 && pcg_rel_tolerance < 1)) Reject("pcg_rel_tolerance", pcg_rel_tolerance, "in (0, 1)");
  if (pcg_max_iterations < 1) Reject("pcg_max_iterations", pcg_max_iterations, ">= 1");
  if (lbfgs_history < 1) Reject("lbfgs_history", lbfgs_history, ">= 1");
  if (!(lbfgs_weight_scale > 0 && lbfgs_weight_scale <= 1))
    Reject("lbfgs_weight_scale", lbfgs_weight_scale, "in (0, 1]");
  if (!(backward_rel_tolerance >= 0 && backward_rel_tolerance < 1))
    Reject("backward_rel_tolerance", backward_rel_tolerance, "in [0, 1) (0: derived from the forward's accuracy)");
  if (!(backward_tolerance_factor > 0 && backward_tolerance_factor <= 1))
    Reject("backward_tolerance_factor", backward_tolerance_factor, "in (0, 1]");
  if (std::find(std::begin(kAdjointSolvers), std::end(kAdjointSolvers), adjoint_solver) == std::end(kAdjointSolvers))
    Reject("adjoint_solver", static_cast<int>(adjoint_solver), "kAuto (0), kIterative (1) or kDirect (2)");
  if (backward_max_iterations < 1) Reject("backward_max_iterations", backward_max_iterations, ">= 1");
  if (adjoint_guess_solutions < 0) Reject("adjoint_guess_solutions", adjoint_guess_solutions, ">= 0");
  if (!(pd_factor_copy_max_bytes >= 0))
    Reject("pd_factor_copy_max_bytes", pd_factor_copy_max_bytes, ">= 0 (0: never a copy, infinity: always)");
  if (!(adjoint_direct_max_bytes >= 0))
    Reject("adjoint_direct_max_bytes", adjoint_direct_max_bytes,
           ">= 0 (0: no direct PD adjoint unless kDirect, infinity: no bound)");
  if (!(max_extent_ratio > 1)) Reject("max_extent_ratio", max_extent_ratio, "> 1 (infinity: no bound)");
  if (num_threads < 0 || num_threads > MaxSolverThreads()) {
    std::ostringstream range;
    range << "in [0, " << MaxSolverThreads() << "] (0: OpenMP default; at most 4 x the " << omp_get_num_procs()
          << " processors)";
    Reject("num_threads", num_threads, range.str().c_str());
  }
}

}  // namespace diffpd
