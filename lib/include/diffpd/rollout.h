// States, per-step inputs, a recorded rollout and the gradients of a loss.
#pragma once

#include <vector>

#include "diffpd/material.h"
#include "diffpd/solver_options.h"
#include "diffpd/state_forces.h"
#include "diffpd/types.h"

namespace diffpd {

// Nodal positions x (m) and velocities v (m/s), each 3n: node i axis d at 3i+d.
struct State {
  VectorXd x;
  VectorXd v;
};

// What drives one step. An empty vector means "none" and costs nothing.
struct StepInput {
  VectorXd external_force;  // 3n, N, applied during the step (explicit)
  // One activation per Scene::muscles entry (muscle.h), finite;
  // empty: all at rest (1). Held during the step.
  VectorXd activation;
  // Scene::quad_hydrodynamics only: which faces feel the water during the
  // step, one entry (1 wet, 0 dry) per face; empty (the default): each
  // face's state decides (WettedQuads, wetted_quads.h). A face held wet
  // where the water does not meet it keeps the wet formula continued past
  // grazing incidence (phi < 0). The forward, Backward and Tangents all
  // follow it. The force jumps where a face switches; holding each step's
  // set at a rollout's own (WettedQuads of its states) makes nearby inputs
  // give that rollout's smooth piece, whose derivative Backward returns,
  // as frictional contact's active sets do for contact (used by gradient
  // checks). Simulate rejects another length or value:
  // "Simulate: inputs[2]: wetted_quads has 3 entries, expected 860 (one per
  // quad_hydrodynamics face)", "... wetted_quads[5] = 7 is invalid: must be 0 or 1".
  std::vector<char> wetted_quads{};
};

// Outcome of one step.
struct StepReport {
  int iterations = 0;           // Newton / PD / L-BFGS iterations (0 for semi-implicit)
  int line_search_steps = 0;    // total backtracking halvings
  double initial_residual = 0;  // ||grad g(x0)||
  double final_residual = 0;    // ||grad g(x_{i+1})||
  double seconds = 0;
  // Solves repeated from x_i because the first result's g was above g(x_i)
  // (SolverOptions::bound_step_energy): 0 or 1.
  int energy_restarts = 0;
  // The solve ended at g's rounding floor above the tolerance
  // (SolverOptions::accept_rounding_floor); final_residual is what it reached.
  bool rounding_floor_stop = false;
  // PD-LBFGS's line search stalled, or it reached max_iterations, and Newton
  // finished the step (SolverOptions::pd_lbfgs_newton_fallback); iterations
  // include Newton's.
  bool newton_fallback = false;
  // Frictional contact (contact.h): the step's final active set (sorted node
  // indices), the contact force on each of those nodes (3 x |set|, N, the
  // surface's push on the node) and the number of active-set passes (solves).
  std::vector<int> contact_nodes;
  Eigen::Matrix3Xd contact_forces;
  int active_set_passes = 0;
};

// A recorded trajectory: states[0..K], inputs[0..K-1]. It stores exactly what
// the backward pass needs: per step 2 x 3n doubles of state plus the step's
// inputs (16 * 3n bytes + inputs per step), and the materials and options it
// was made with. Nothing per iteration is kept. With frictional contact the
// backward pass reads each step's active set from `reports`.
struct Rollout {
  std::vector<State> states;
  std::vector<StepInput> inputs;
  std::vector<StepReport> reports;
  MaterialParameters material;  // the base material (Scene::material)
  // One per Scene::material_regions entry, in order (empty without regions).
  std::vector<MaterialParameters> region_materials;
  SolverOptions options;
  // Closed loop (Simulator::Simulate with a Controller, controller.h): the
  // controller's memory m_0..m_K and the parameters it acted with; `inputs`
  // hold its actions. Both empty for an open-loop rollout.
  std::vector<VectorXd> controller_memory;
  VectorXd controller_parameters;

  int num_steps() const { return static_cast<int>(inputs.size()); }
  bool closed_loop() const { return !controller_memory.empty(); }
  double forward_seconds() const;
  // The rollout truncated after `num_steps` steps: states[0..num_steps],
  // inputs[0..num_steps), the reports of those steps (as many as there are),
  // the same materials and options (closed loop: controller_memory[0..num_steps]
  // and the controller's parameters). Simulator::Backward on it gives the
  // gradient of a loss that reads states 0..num_steps only, at num_steps
  // adjoint steps instead of K; its per-step gradients then have num_steps
  // entries. Throws InvalidInputError unless 0 <= num_steps <= K
  // ("Truncated: num_steps = 7 is out of range [0, 5]").
  Rollout Truncated(int num_steps) const;
};

// dL/dx_k and dL/dv_k of a loss for k = 0..K (each 3n, or empty for zero).
struct LossGradient {
  std::vector<VectorXd> dx;
  std::vector<VectorXd> dv;
  // Sizes both lists for K steps with empty (zero) entries.
  explicit LossGradient(int num_steps = 0) : dx(num_steps + 1), dv(num_steps + 1) {}
};

struct BackwardReport {
  int linear_iterations = 0;  // iterations of the iterative adjoint solves, summed
  int fallbacks = 0;          // adjoint solves that fell back to a direct solve
  // Steps whose adjoint (tangent: whose P columns') system was solved by an
  // iteration (PD's, or newton-pcg's PCG; a fallback still counts here) and
  // by a factorisation of the step Hessian (newton-cholesky, newton-ldlt,
  // and the PD methods' direct adjoint: SolverOptions::adjoint_solver).
  int iterative_steps = 0;
  int direct_steps = 0;
  // Steps whose exact step Hessian H a Cholesky factorisation found not
  // positive definite (then solved by sparse LU). The forward stopped such a
  // step away from a minimum of its energy (e.g. a loose tolerance), and the
  // gradient through it can differ from the converged rollout's by orders of
  // magnitude: tighten rel_tolerance. (newton-ldlt's LDL^T factorises an
  // indefinite H without noticing: not counted there.)
  int indefinite_steps = 0;
  double seconds = 0;
  // Backward over a checkpointed rollout (checkpointed_rollout.h): forward
  // steps it recomputed, and the most states (2 x 3n doubles each) held at
  // once, the rollout's included. Zero otherwise.
  int recomputed_steps = 0;
  int peak_states = 0;
};

// dL/d(input) for every differentiable input of a rollout.
struct RolloutGradient {
  VectorXd x0;                           // 3n
  VectorXd v0;                           // 3n
  std::vector<VectorXd> external_force;  // per step, 3n
  std::vector<VectorXd> activation;      // per step, one per muscle (empty if none)
  StateForceGradient state_forces;       // declared state-force parameters
  // The base material's parameters (Scene::material; elements in no region).
  double youngs_modulus = 0;  // dL/dE, per Pa
  double poissons_ratio = 0;  // dL/dnu
  double density = 0;         // dL/drho, per kg/m^3
  // One per Scene::material_regions entry, in order (empty without regions):
  // dL/dE_r (per Pa), dL/dnu_r, dL/drho_r (per kg/m^3) of region r.
  std::vector<MaterialComponents> region_materials;
  // Closed loop (Backward with the rollout's controller): dL/dtheta of the
  // controller's parameters and dL/dm_0 of its initial memory; empty
  // otherwise. `activation` and `external_force` then hold dL/du_k, the
  // gradients w.r.t. the recorded actions.
  VectorXd controller_parameters;
  VectorXd controller_memory;
  BackwardReport report;
};

}  // namespace diffpd
