// Backtracking (Armijo) line search shared by Newton and PD-LBFGS (internal).
#pragma once

#include "solver/simulator_impl.h"

namespace diffpd::internal {

// Tries x + alpha d for alpha = 1, 1/2, 1/4, ... until
//   g(x + alpha d) <= g(x) + c alpha grad^T d,
// or, where g cannot resolve the change (it is within 1e-12 |g|, or the
// predicted decrease -grad^T d and the change are both within 1e-10 |g|:
// near convergence), until |grad g| strictly decreases.
// On success sets *x, *value, *grad to the accepted point and returns the
// number of halvings with at_rounding_floor false. When no step is accepted
// within the limit at |grad g| <= StepObjective::kRoundingFloorStall times
// the objective's rounding floor, and SolverOptions::accept_rounding_floor,
// returns with at_rounding_floor true and x unchanged: the solve ends there.
// Throws SolverError(kNonFinite) when the slope grad^T d is not finite or g
// is not finite at any trial point,
// SolverError(kLineSearchFailed) when d is not a descent direction or for
// any other stall (the message gives |grad g| and the floor).
struct LineSearchResult {
  int halvings = 0;
  bool at_rounding_floor = false;
};
LineSearchResult BacktrackingLineSearch(StepObjective& objective, const VectorXd& d, VectorXd* x, double* value,
                                        VectorXd* grad);

}  // namespace diffpd::internal
