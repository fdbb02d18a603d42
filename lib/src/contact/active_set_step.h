// One implicit step with frictional contact, and its backward terms
// (internal). The model is documented in diffpd/contact.h.
#pragma once

#include <functional>
#include <vector>

#include "contact/contact_pin_scope.h"
#include "diffpd/contact.h"
#include "diffpd/rollout.h"
#include "diffpd/types.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

// Where a candidate node is pinned from its previous state (x, v) with time
// step h, and d pin / dx, d pin / dv (3x3 each); see diffpd/contact.h. The
// current rule, Project(x), does not depend on v and h (d_dv = 0); callers
// pass them so that they need not know the rule.
struct ContactPin {
  Vec3 position;
  Mat3 d_dx;
  Mat3 d_dv;
};
ContactPin ComputeContactPin(const ContactSurface& surface, const Vec3& x, const Vec3& v, double h);

// The active-set loop of one step from `state` with explicit force `force`
// (3n). Fills report (iterations summed over passes, contact_nodes,
// contact_forces, active_set_passes) and returns x_{i+1}. Throws
// SolverError(kActiveSetNotConverged) after max_passes solves, and
// SolverError(kContactEnergyGain) when a step with pinned nodes gains more
// energy than FrictionalContactOptions::max_energy_gain allows.
VectorXd SolveWithActiveSet(SimulatorImpl& sim, const State& state, const VectorXd& force, const ImplicitSolver& solve,
                            StepReport* report);

// Backward of the pins of one step, with its active set `nodes` pinned (a
// ContactPinScope alive) and z = H^-1 b the step's adjoint: dL/dpin =
// b - (H z) at the pinned nodes, chained through pin(x_i, v_i) into *gx, *gv.
void AddPinGradient(SimulatorImpl& sim, StepLinearization& lin, const State& previous, const std::vector<int>& nodes,
                    const VectorXd& b, const VectorXd& z, VectorXd* gx, VectorXd* gv);

}  // namespace diffpd::internal
