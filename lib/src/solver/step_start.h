// Where an implicit step's solve starts (internal).
//
// Every implicit method solves x_{i+1} = argmin g(x) by a descent from its
// start, so g(x_{i+1}) <= g(start). From the predictor x_i + h v_i alone
// nothing bounds the result by the previous state: for very stiff or nearly
// incompressible material at large h the predictor can be so compressed that
// the descent ends at a far stationary point holding many times the energy
// the body had (the stress report found a cantilever at E = 1e10 Pa,
// nu = 0.499, h = 0.01 s go from 12 J to 5.6e6 J in one step). Since
//   g(x_i) = 1/2 v_i^T M v_i + E(x_i) - f^T x_i,
// the previous total energy, starting from x_i whenever g is lower there
// than at the predictor guarantees
//   E(x_{i+1}) - f^T x_{i+1} + 1/2 |v_{i+1} - v_i|_M^2 <= 1/2 v_i^T M v_i + E(x_i) - f^T x_i:
// a step never lifts the potential energy above the previous total energy
// (f: the step's explicit force, incl. gravity; without frictional-contact
// pins, which move nodes). The convergence test stays relative to
// |grad g(x_i + h v_i)| whichever start is taken.
#pragma once

#include "solver/simulator_impl.h"

namespace diffpd::internal {

// `predicted` (x_i + h v_i) and `previous` (x_i), both with the Dirichlet
// values set. Returns `predicted` at once unless
// SolverOptions::start_at_lower_energy. Evaluates g at both (one evaluation more than starting at the
// predictor: the chosen start's is primed for the solver's first Evaluate),
// sets the objective's reference residual to |grad g(predicted)| and returns
// the start. An evaluation error at `previous` (e.g. an inverted element in
// a user's state) leaves the predictor as the start; one at `predicted`
// propagates, as it would from the solver.
VectorXd ChooseStepStart(StepObjective& objective, const VectorXd& predicted, const VectorXd& previous);

}  // namespace diffpd::internal
