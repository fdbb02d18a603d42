#include "solver/adjoint_work.h"

namespace diffpd::internal {
namespace {

// Seconds per unit of work on one core of the reference machine (2-core
// x86-64, one thread), fitted by least squares (relative residuals) to the
// CPU times of 750 iterative and 3 578 direct adjoint steps on 21 problems
// of `diffpd tradeoff`
// (docs/benchmarks.md, "The automatic adjoint's cost model"); per problem
// the fit's total is within 0.82-1.13x (iteration) and 0.81-1.04x (direct
// solve) of the measured one.
// The iteration.
constexpr double kProductEntry = 2.4e-10;  // per packed entry of one product with H
constexpr double kPdSolveEntry = 3.1e-10;  // per factor entry of one triangular sweep, per vector
constexpr double kIterationDof = 5.6e-9;   // per DoF of one iteration's vector passes, per vector
constexpr double kIterativeCall = 5.0e-5;  // per solve (set-up, the guess's small dense system)
// The direct solve (numeric factorisation and solve; the assembly is the
// per-DoF term).
constexpr double kFactorFlop = 9.1e-11;       // per flop of the numeric factorisation
constexpr double kFactorEntry = 1.24e-8;      // per factor entry, per factorisation
constexpr double kDirectDof = 2.77e-7;        // per DoF, per factorisation
constexpr double kDirectSolveEntry = 1.0e-9;  // per factor entry of one triangular sweep, per vector
// The one-off symbolic analysis (with the first factorisation's set-up).
constexpr double kAnalysisEntry = 4.0e-8;  // per factor entry
constexpr double kAnalysisCall = 3.5e-4;

}  // namespace

double IterativeSeconds(const AdjointWorkSizes& sizes, const IterativeWork& work) {
  return kIterativeCall + work.hessian_products * kProductEntry * sizes.packed_entries +
         work.pd_solves * kPdSolveEntry * 2 * sizes.pd_solve_entries + work.iterations * kIterationDof * sizes.dofs;
}

double DirectSeconds(const AdjointWorkSizes& sizes, int columns) {
  return kFactorFlop * sizes.hessian_factor_flops + kFactorEntry * sizes.hessian_factor_entries +
         kDirectDof * sizes.dofs + columns * kDirectSolveEntry * 2 * sizes.hessian_factor_entries;
}

double AnalysisSeconds(const AdjointWorkSizes& sizes) {
  return kAnalysisCall + kAnalysisEntry * sizes.hessian_factor_entries;
}

}  // namespace diffpd::internal
