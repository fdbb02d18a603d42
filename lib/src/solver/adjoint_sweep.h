// The reverse sweep of Simulator::Backward, one step at a time (internal).
//
// Backward over a stored rollout (simulator.cc) and over a checkpointed one
// (checkpointed_rollout.cc) run the same sweep: the steps K-1, ..., 0 in
// that order, each given its two states, input and forward report, so the
// two give bit-identical gradients when their states are identical. The
// sweep carries the adjoint (dL/dx_{i+1}, dL/dv_{i+1}), the adjoint guesses
// recycled from the steps solved before (adjoint_recycling.h) and the
// material and state-force gradients summed over the steps.
#pragma once

#include <functional>

#include "diffpd/controller.h"
#include "diffpd/rollout.h"
#include "solver/adjoint_recycling.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

class AdjointSweep {
 public:
  // A sweep over `steps` steps of a rollout made with `forward_options`
  // (its rel_tolerance sets the adjoint tolerance, adjoint_tolerance.h, and
  // its svd_warm_start whether every step's SVDs start cold),
  // starting from dL/dx_K = dx_last and dL/dv_K = dv_last (3n each, or empty
  // for zero). `controller` (not owned; nullptr: open loop) made the rollout.
  // With keep_step_gradients false the per-step gradients are not kept in
  // the result (its external_force and activation lists stay empty).
  AdjointSweep(SimulatorImpl& sim, int steps, const SolverOptions& forward_options, const VectorXd& dx_last,
               const VectorXd& dv_last, const Controller* controller, bool keep_step_gradients = true);

  // Step i (called for i = K-1 down to 0, each once): s0 = x_i, v_i and
  // s1 = x_{i+1}, v_{i+1}; `report`: the step's forward report (nullptr if
  // none; frictional contact needs its active set); `memory`: the
  // controller's memory m_i (closed loop only); dx_i, dv_i: dL/dx_i and
  // dL/dv_i (empty: zero). Afterwards step_external_force() and
  // step_activation() hold step i's input gradients.
  void Step(int i, const State& s0, const State& s1, const StepInput& input, const StepReport* report,
            const VectorXd* memory, const VectorXd& dx_i, const VectorXd& dv_i);
  const VectorXd& step_external_force() const { return external_force_; }
  const VectorXd& step_activation() const { return activation_; }

  // The gradient after step 0. Throws SolverError(kNonFinite) when a
  // component is not finite.
  RolloutGradient Finish();

 private:
  SimulatorImpl& sim_;
  double forward_rel_tolerance_;
  bool svd_warm_start_;  // the forward's SolverOptions::svd_warm_start
  const Controller* controller_;
  bool keep_;
  RolloutGradient out_;
  VectorXd gx_, gv_;
  VectorXd g_memory_;  // dL/dm_{i+1} of the controller (empty: zero)
  // Material adjoints per part (0: base, r + 1: region r): Lame parameters,
  // and dL/dM (3n), turned into densities at the end (M = sum_p rho_p m_p).
  VectorXd dmu_, dlambda_, dmass_;
  VectorXd gravity_;
  VectorXd external_force_, activation_;
  bool finite_steps_ = true;
  AdjointRecycling recycling_;
};

}  // namespace diffpd::internal
