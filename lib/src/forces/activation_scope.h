// Muscle activation of the step being solved or differentiated (internal).
#pragma once

#include "diffpd/types.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

// Throws InvalidInputError unless `activation` is empty or has one finite
// entry per muscle (negative ones included):
//   "activation has 3 entries, expected 2 (one per muscle)",
//   "activation[1] = nan is invalid: must be finite".
void CheckActivation(const VectorXd& activation, int num_muscles);

// Sets sim.activation for its lifetime and restores the previous value.
class ActivationScope {
 public:
  ActivationScope(SimulatorImpl& sim, const VectorXd& activation) : sim_(sim), saved_(std::move(sim.activation)) {
    sim.activation = activation;
  }
  ~ActivationScope() { sim_.activation = std::move(saved_); }
  ActivationScope(const ActivationScope&) = delete;
  ActivationScope& operator=(const ActivationScope&) = delete;

 private:
  SimulatorImpl& sim_;
  VectorXd saved_;
};

}  // namespace diffpd::internal
