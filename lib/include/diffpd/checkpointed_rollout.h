// A rollout recorded in bounded memory: a few checkpoint states instead of
// every step's, the rest recomputed by the backward pass
// (Simulator::SimulateCheckpointed and Simulator::Backward, simulator.h).
//
// The checkpoints follow the binomial schedule of Griewank's "revolve": with
// c checkpoints, a horizon of K steps is reversed with every step recomputed
// at most t times, t the least integer with (c + t)! / (c! t!) >= K (c = 48:
// t = 2 up to 1225 steps, t = 3 up to 20825). The recomputed steps repeat the
// forward's solves exactly (same states, options and initial guesses; every
// step's SVDs start cold, SolverOptions::svd_warm_start = false), so the
// gradients are those of a stored rollout (Simulator::Simulate) made with
// svd_warm_start = false bit for bit wherever the backward itself is
// deterministic (a fixed SolverOptions::adjoint_solver, or kAuto on
// simulators with the same earlier passes: its estimates remember them),
// and those of the default (warm) stored rollout to
// rounding.
#pragma once

#include <functional>
#include <vector>

#include "diffpd/material.h"
#include "diffpd/rollout.h"
#include "diffpd/solver_options.h"

namespace diffpd {

struct CheckpointOptions {
  // States the rollout keeps besides its initial and final ones; >= 1. Its
  // backward pass holds at most as many again while it runs, and two more:
  // at most 2 c + 4 states of 2 x 3n doubles each at once (c = 48: 100
  // states, what a stored rollout of 99 steps keeps;
  // BackwardReport::peak_states). Fewer checkpoints: more recomputed steps.
  int num_checkpoints = 48;
  // Throws InvalidInputError ("checkpoint options: num_checkpoints = 0 is
  // invalid: must be >= 1").
  void Validate() const;
};

// A forward rollout of K steps of which only the checkpoints are kept.
struct CheckpointedRollout {
  State initial;                      // x_0, v_0
  State final;                        // x_K, v_K
  std::vector<int> checkpoint_steps;  // ascending, in (0, K)
  std::vector<State> checkpoints;     // the states at those steps
  // The report of the step that reached each checkpoint, and of the last
  // step (frictional contact's active sets, the residuals the adjoint
  // tolerance follows).
  std::vector<StepReport> checkpoint_reports;
  StepReport final_report;
  std::vector<StepInput> inputs;  // K inputs, as given (empty ones cost nothing)
  MaterialParameters material;    // the base material (Scene::material)
  // One per Scene::material_regions entry, in order (empty without regions).
  std::vector<MaterialParameters> region_materials;
  // The forward's, with svd_warm_start false whatever the simulator's;
  // recomputed steps use them again.
  SolverOptions options;
  CheckpointOptions checkpoint_options;
  // The forward pass's wall seconds and solver iterations, all steps.
  double forward_seconds = 0;
  long forward_iterations = 0;

  int num_steps() const { return static_cast<int>(inputs.size()); }
  // Bytes of the states kept (initial, final and checkpoints; x and v).
  long stored_state_bytes() const;
};

// A loss's derivatives w.r.t. the states of a checkpointed rollout, asked
// for state by state as the backward pass meets them, and where the per-step
// input gradients go: nothing of size K x 3n needs to be held.
struct StateLossGradient {
  // Called for k = K, K-1, ..., 0, once each, with state k: sets *dx =
  // dL/dx_k and *dv = dL/dv_k (3n each; left empty: zero). Empty function:
  // the loss reads no state (every dL/dx_k, dL/dv_k zero).
  std::function<void(int k, const State& state, VectorXd* dx, VectorXd* dv)> state_gradient;
  // Called for steps k = K-1, ..., 0 with dL/df_k (3n, N^-1 units of the
  // loss) and dL/da_k (one per muscle; empty without muscles). Empty
  // function: both are kept in RolloutGradient::external_force and
  // activation (K x 3n doubles); else those lists stay empty.
  std::function<void(int k, const VectorXd& external_force, const VectorXd& activation)> step_gradient;
};

}  // namespace diffpd
