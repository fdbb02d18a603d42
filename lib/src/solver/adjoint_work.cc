#include "solver/adjoint_work.h"

namespace diffpd::internal {
namespace {

// Seconds per unit of work on one core of the reference machine (fitted to
// per-step CPU times of both solvers on every problem of `diffpd tradeoff`;
// docs/benchmarks.md, "The automatic adjoint's cost model").
constexpr double kProductEntry = 1.0e-9;     // per packed entry of an H product
constexpr double kPdSolveEntry = 1.0e-9;     // per factor entry of a triangular sweep, per vector
constexpr double kIterationDof = 1.0e-9;     // per DoF of an iteration's vector passes
constexpr double kAssemblyEntry = 1.0e-9;    // per packed entry assembled into H
constexpr double kFactorFlop = 1.0e-10;      // per flop of the numeric factorisation
constexpr double kFactorCall = 1.0e-5;       // per numeric factorisation
constexpr double kDirectSolveEntry = 1.0e-9;  // per factor entry of a triangular sweep, per vector
constexpr double kAnalysisEntry = 1.0e-8;    // per entry of H's factor, once

}  // namespace

double IterativeSeconds(const AdjointWorkSizes& sizes, const IterativeWork& work) {
  return work.hessian_products * kProductEntry * sizes.packed_entries +
         work.pd_solves * kPdSolveEntry * 2 * sizes.pd_solve_entries + work.iterations * kIterationDof * sizes.dofs;
}

double DirectSeconds(const AdjointWorkSizes& sizes, int columns) {
  return kAssemblyEntry * sizes.packed_entries + kFactorFlop * sizes.hessian_factor_flops + kFactorCall +
         columns * kDirectSolveEntry * 2 * sizes.hessian_factor_entries;
}

double AnalysisSeconds(const AdjointWorkSizes& sizes) { return kAnalysisEntry * sizes.hessian_factor_entries; }

}  // namespace diffpd::internal
