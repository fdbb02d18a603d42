// The simulator: steps a scene forward in time and differentiates rollouts.
//
//   Simulator sim(scene, options);
//   Rollout r = sim.Simulate(sim.RestState(), std::vector<StepInput>(25));
//   LossGradient dl(r.num_steps());  dl.dx.back() = ...;
//   RolloutGradient g = sim.Backward(r, dl);
//
// The simulator owns a copy of the scene, its FEM data and its solver caches
// (the PD factor is computed once per (h, densities, stiffnesses) and reused
// for every step, iteration and rollout). It is not thread-safe; use one per thread.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "diffpd/checkpointed_rollout.h"
#include "diffpd/controller.h"
#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/solver_options.h"
#include "diffpd/tangent_rollout.h"

namespace diffpd {

namespace internal {
class SimulatorImpl;
}

class Simulator {
 public:
  // Validates scene and options (InvalidInputError) and precomputes the FEM data.
  Simulator(const Scene& scene, const SolverOptions& options);
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  const Scene& scene() const;
  const SolverOptions& options() const;
  int num_dofs() const;
  // Replaces the options (validated). The PD factor is recomputed lazily,
  // only if the time step changed.
  void SetOptions(const SolverOptions& options);
  // Replaces the base material (validated); the PD factor follows lazily.
  void SetMaterial(const MaterialParameters& material);
  // Replaces the material of Scene::material_regions[region] (validated);
  // the PD factor follows lazily. Throws InvalidInputError for a region out
  // of range ("SetRegionMaterial: region 2 is out of range [0, 2)") or an
  // invalid material ("SetRegionMaterial: region 0: youngs_modulus = -1 is
  // invalid: ...").
  void SetRegionMaterial(int region, const MaterialParameters& material);

  // Rest positions (Dirichlet DoFs at their prescribed values), zero velocity.
  State RestState() const;
  // Lumped mass per DoF (3n, kg).
  VectorXd LumpedMass() const;
  // Total elastic energy E(x) (J) of the scene at positions x (3n).
  double ElasticEnergy(const VectorXd& x);
  // Semi-implicit Euler's stability limit at positions x (3n), with the
  // muscles at `activation` (empty: zero): an estimate (s) of the largest
  // stable time step, 2 / omega_max, omega_max^2 the largest eigenvalue of
  // M^-1 K over the free DoFs, M the lumped mass and K the Hessian of the
  // elastic, muscle and penalty-contact energies at x. Computed by Lanczos
  // iteration to about 1e-6 relative, from below, so the step is at most
  // that much above the limit of the linearised dynamics; damping and the
  // other state forces are not included, and a deformed or moving body's
  // limit differs. +infinity where nothing is stiff (every DoF fixed).
  // Throws InvalidInputError for x or activation of the wrong size or with
  // a non-finite entry ("ExplicitStableTimeStep: x has 5 entries, expected
  // 48 (3 x number of nodes)").
  double ExplicitStableTimeStep(const VectorXd& x, const VectorXd& activation = VectorXd());

  // One time step with the configured method. Throws InvalidInputError on
  // mismatched sizes or non-finite input, SolverError when the step fails
  // (non-convergence, inverted neo-Hookean element, factorisation failure,
  // kNonFinite for a residual or state that overflows, kDiverged for a body
  // stretched beyond SolverOptions::max_extent_ratio).
  State Step(const State& state, const StepInput& input, StepReport* report = nullptr);
  // K = inputs.size() steps from `initial`, recorded for Backward(). Every
  // input is checked first: InvalidInputError names one of the wrong size
  // or with a non-finite entry ("Simulate: inputs[2]: external_force has a
  // non-finite entry"); the step's own exceptions otherwise.
  Rollout Simulate(const State& initial, const std::vector<StepInput>& inputs);
  // Closed loop (controller.h): `steps` steps from `initial`, each driven by
  // the action the controller chooses from the step's state and its memory.
  // The rollout records the actions as its inputs, the memory and the
  // controller's parameters. Throws InvalidInputError for steps < 0, an
  // action of the wrong size or with an invalid entry ("Simulate: the
  // controller's action at step 3: activation[1] = nan is invalid: must be
  // finite") or a memory of the wrong size or non-finite ("Simulate:
  // the controller's memory after step 0 has 3 entries, expected 4"); the
  // step's own exceptions otherwise.
  Rollout Simulate(const State& initial, const Controller& controller, int steps);
  // Reverse mode: gradients of a loss L(x_0..x_K, v_0..v_K) w.r.t. every
  // differentiable input, given dL/dx_k and dL/dv_k (material parameters:
  // the base material's and, per region, RolloutGradient::region_materials).
  // The rollout must come from this simulator with the same materials (base
  // and regions), time step and method. Throws InvalidInputError naming the
  // first problem: a rollout without one more state than inputs, a state
  // whose x or v is not 3n finite entries, an input whose external force or
  // activation has the wrong size or a non-finite entry, a rollout made with
  // other settings, a frictional-contact rollout without its reports (e.g.
  // "Backward: the rollout's state 1 has x with 24 entries, expected 48 (3 x
  // number of nodes)"), or a loss gradient of the wrong shape.
  // A closed-loop rollout's actions count here as given inputs (the
  // gradients w.r.t. them are `activation` and `external_force`).
  RolloutGradient Backward(const Rollout& rollout, const LossGradient& loss);
  // Closed loop: Backward through the controller that made the rollout
  // (controller.h), which also fills RolloutGradient::controller_parameters
  // and controller_memory. Throws InvalidInputError, besides the above, for
  // an open-loop rollout ("Backward: the rollout is open-loop (made without
  // a controller)") or a controller whose parameters or memory size differ
  // from the rollout's ("Backward: the controller's parameters differ from
  // those the rollout was made with").
  RolloutGradient Backward(const Rollout& rollout, const LossGradient& loss, const Controller& controller);
  // K = inputs.size() steps from `initial` keeping only the checkpoints of
  // `checkpoints` (checkpointed_rollout.h): memory independent of K but for
  // the inputs. `observer` (optional) sees every state k = 0..K as it is
  // computed (e.g. to evaluate a loss). Throws as Step and
  // CheckpointOptions::Validate.
  CheckpointedRollout SimulateCheckpointed(const State& initial, const std::vector<StepInput>& inputs,
                                           const CheckpointOptions& checkpoints = CheckpointOptions(),
                                           const std::function<void(int k, const State& state)>& observer = nullptr);
  // Backward over a checkpointed rollout: the steps between checkpoints are
  // recomputed with the rollout's forward options, and the gradient is the
  // stored rollout's (bit for bit with a fixed SolverOptions::adjoint_solver
  // and svd_warm_start = false, to rounding with warm SVDs).
  // BackwardReport::recomputed_steps and peak_states say what it cost. The
  // same preconditions as Backward on a stored rollout (open loop), and
  // InvalidInputError for checkpoints other than SimulateCheckpointed's
  // ("Backward: the checkpointed rollout's checkpoints are not those
  // SimulateCheckpointed keeps for its number of steps and checkpoint
  // options"), options with svd_warm_start = true, or a state with the
  // wrong size or a non-finite entry.
  RolloutGradient Backward(const CheckpointedRollout& rollout, const LossGradient& loss);
  // The same with the loss's state derivatives asked for as the states are
  // recomputed, and the per-step gradients passed on (StateLossGradient):
  // memory independent of K. InvalidInputError for a loss derivative of the
  // wrong size or non-finite ("Backward: the loss's dL/dx_3 has 5 entries,
  // expected 0 or 48 finite ones (3 x number of nodes)").
  RolloutGradient Backward(const CheckpointedRollout& rollout, const StateLossGradient& loss);
  // Forward mode: tangents of every state of the rollout along each of the
  // P directions (tangent_rollout.h), all P solved together per step with the
  // step's exact Hessian H (PD: the forward factor of A, A z = b + dA z or
  // L-BFGS; Newton: one factorisation of H):
  //   H dx_{i+1} = M (dx_i + h dv_i) / h^2 + df_i - d(grad g)/dtheta . dtheta,
  //   dv_{i+1} = (dx_{i+1} - dx_i) / h.
  // Same preconditions and exceptions as Backward; InvalidInputError also for
  // no direction or a direction with wrongly sized or non-finite entries.
  // A closed-loop rollout's actions are held fixed (open-loop tangents).
  TangentRollout Tangents(const Rollout& rollout, const std::vector<InputDirection>& directions);
  // Forward mode over a checkpointed rollout: its states are recomputed from
  // the initial one alongside the tangents (one forward step per step, with
  // the rollout's forward options), so the tangents are the stored
  // rollout's, bit for bit with a fixed SolverOptions::adjoint_solver and
  // svd_warm_start = false. With
  // a consumer (tangent_rollout.h) every state and its tangents go to it as
  // they are computed and TangentRollout::dx and dv stay empty (memory
  // independent of K); without, they hold every state's tangents. The
  // preconditions and exceptions of Backward over a checkpointed rollout and
  // of Tangents.
  TangentRollout Tangents(const CheckpointedRollout& rollout, const std::vector<InputDirection>& directions,
                          const TangentConsumer& consumer = nullptr);

  // Equilibrium under the declared forces (gravity, `input.external_force`)
  // and Dirichlet conditions, by Newton (newton-pcg if that is the method,
  // else newton-cholesky), starting from `initial_positions` (3n).
  VectorXd SolveQuasiStatic(const VectorXd& initial_positions, const StepInput& input, StepReport* report = nullptr);

  // Number of numeric factorisations of the PD matrix A so far.
  int num_pd_factorizations() const;
  // Wall seconds those factorisations took (assembly of A, symbolic analysis,
  // numeric factorisation), all of them so far: the one-off cost a PD method
  // pays per (mesh, h, material weights, Dirichlet set), shared by every
  // iteration, step and rollout after it.
  double pd_factorization_seconds() const;
  // Bytes of the PD factor's copy for parallel solves in use: 0 before a PD
  // method has stepped, or where the copy would exceed
  // SolverOptions::pd_factor_copy_max_bytes and CHOLMOD solves instead.
  std::size_t pd_factor_copy_bytes() const;

 private:
  // Backward after the rollout's checks, with an optional controller
  // (nullptr: open loop).
  RolloutGradient CheckedBackward(const Rollout& rollout, const LossGradient& loss, const Controller* controller);

  std::unique_ptr<internal::SimulatorImpl> impl_;
};

}  // namespace diffpd
