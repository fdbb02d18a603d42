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

  int num_steps() const { return static_cast<int>(inputs.size()); }
  double forward_seconds() const;
  // The rollout truncated after `num_steps` steps: states[0..num_steps],
  // inputs[0..num_steps), the reports of those steps (as many as there are),
  // the same materials and options. Simulator::Backward on it gives the
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
  double seconds = 0;
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
  BackwardReport report;
};

}  // namespace diffpd
