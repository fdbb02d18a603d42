// The forward's options while a derivative pass recomputes steps (internal;
// checkpointed_rollout.h).
#pragma once

#include "diffpd/solver_options.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

// Sets the simulator's options to a rollout's forward options for its
// lifetime and restores them after: a recomputed step repeats the forward's
// solve exactly (tolerances, threads), whatever backward settings the
// simulator has now.
class ForwardOptionsScope {
 public:
  ForwardOptionsScope(SimulatorImpl& sim, const SolverOptions& forward) : sim_(sim), saved_(sim.options) {
    sim.options = forward;
  }
  ~ForwardOptionsScope() { sim_.options = saved_; }
  ForwardOptionsScope(const ForwardOptionsScope&) = delete;
  ForwardOptionsScope& operator=(const ForwardOptionsScope&) = delete;

 private:
  SimulatorImpl& sim_;
  SolverOptions saved_;
};

}  // namespace diffpd::internal
