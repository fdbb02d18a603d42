// One implicit step solved so that it cannot gain energy by landing on a far
// stationary point (internal).
//
// Every implicit method solves x_{i+1} = argmin g(x) by a descent from
// x0 = x_i + h v_i, so g(x_{i+1}) <= g(x0); nothing bounds the result by the
// previous state. For very stiff or nearly incompressible material at large h
// the predictor can be so compressed that the descent ends at a far
// stationary point holding many times the body's energy (the stress report
// found a cantilever at E = 1e10 Pa, nu = 0.499, h = 0.01 s go from 12 J to
// 5.6e6 J in one step, with |grad g| meeting the test). Since
//   g(x_i) = 1/2 v_i^T M v_i + E(x_i) - f^T x_i
// is the previous total energy, a result with g above g(x_i) is such a
// point: the step is then solved again from x_i, and descent from there gives
//   E(x_{i+1}) - f^T x_{i+1} + 1/2 |v_{i+1} - v_i|_M^2 <= g(x_i),
// i.e. the new potential energy never exceeds the previous total energy (f:
// the step's explicit force, gravity included). Steps whose first result is
// below g(x_i) (all but such extreme ones) are returned as solved from x0,
// so accuracy at a given tolerance is unchanged. The convergence test stays
// relative to |grad g(x0)|.
#pragma once

#include "solver/simulator_impl.h"

namespace diffpd::internal {

// `predicted` (x0) and `previous` (x_i), both with the Dirichlet values set
// (with frictional contact: each active-set pass's solve, with that pass's
// pins; a pass paused at its screening checkpoint is not checked).
// With SolverOptions::bound_step_energy off: solve(objective, predicted).
// Otherwise, after that solve, one evaluation of g at x_i; if the result's g
// is above it by more than the solve's tolerance and g's rounding allow
// (|grad g| |x - x_i| + 1e-9 (|g(x)| + |g(x_i)|)), a second solve from x_i
// (its iterations are added to the report, and report->energy_restarts
// counts it). An evaluation error at x_i
// (an inverted element in a user's state) keeps the first result.
VectorXd SolveEnergyBounded(StepObjective& objective, const VectorXd& predicted, const VectorXd& previous,
                            const ImplicitSolver& solve, StepReport* report);

}  // namespace diffpd::internal
