// Semi-implicit Euler's stability limit (internal).
#pragma once

#include "diffpd/types.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

// The largest time step (s) at which semi-implicit Euler is stable when
// linearised at positions x (3n): 2 / omega_max, omega_max^2 the largest
// eigenvalue of M^-1 K over the free DoFs, M the lumped mass and K the exact
// Hessian of the elastic and auxiliary energies (muscles at sim.activation,
// penalty contact) at x. omega_max^2 comes from the Lanczos iteration on
// M^-1/2 K M^-1/2 from a fixed pseudo-random start, stopped when the largest
// Ritz value's residual is below 1e-6 of it (its error is then far smaller)
// or after 500 iterations; a Ritz value never exceeds the eigenvalue, so
// the step returned is at least the true limit and within about 1e-6 of it.
// +infinity where K has no positive eigenvalue (every DoF fixed, or no
// stiffness). Damping and the state forces are not included.
double ExplicitStableTimeStep(SimulatorImpl& sim, const VectorXd& x);

}  // namespace diffpd::internal
