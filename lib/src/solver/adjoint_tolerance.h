// The relative tolerance of one step's adjoint or tangent solve (internal;
// SolverOptions::backward_rel_tolerance and backward_tolerance_factor).
//
// A fixed backward_rel_tolerance (> 0) is used as given. At 0 (the default)
// it follows the accuracy the step's forward solve reached:
//
//   tol_i = backward_tolerance_factor * min(r_i, rel_tolerance),
//   r_i = final_residual_i / initial_residual_i (StepReport),
//
// rel_tolerance being the forward's (the min only where it is > 0), and
// tol_i not below kMinAdjointRelTolerance. A step without a report, or
// with a zero initial residual (it started at its solution), takes
// r_i = rel_tolerance. The factor's default is checked by
// adjoint_tolerance_test (a small beam: within 1.5x of the exact adjoint's
// gradient error); benchmarks/backward_benchmark --sweep measures the
// gradient error against the adjoint tolerance on larger scenes.
#pragma once

#include "diffpd/rollout.h"
#include "diffpd/solver_options.h"

namespace diffpd::internal {

// Below it CG's recomputed residual no longer settles in double precision.
inline constexpr double kMinAdjointRelTolerance = 1e-12;

// `options`: the simulator's (backward settings); `forward_rel_tolerance`:
// that of the rollout's forward solves; `forward`: the step's report, or
// nullptr.
double AdjointRelTolerance(const SolverOptions& options, double forward_rel_tolerance, const StepReport* forward);

}  // namespace diffpd::internal
