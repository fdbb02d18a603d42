// The preconditions Backward and Tangents share on the rollout they
// differentiate (internal).
#pragma once

#include <string>

#include "diffpd/checkpointed_rollout.h"
#include "diffpd/rollout.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

// Throws InvalidInputError, the message starting with `caller` ("Backward",
// "Tangents"), unless `rollout` can be differentiated by `sim`:
//  - K inputs and K + 1 states: "Backward: the rollout has 4 states for 2 inputs (needs one more state than
//    inputs)";
//  - every state's x and v of 3n finite entries: "Backward: the rollout's state 1 has x with 24 entries, expected
//    48 (3 x number of nodes)", "Backward: the rollout's state 1 has a non-finite entry in v";
//  - every input's external force empty or 3n finite entries, its activation
//    empty or one finite entry >= 0 per muscle: "Backward: the rollout's input
//    0 has external_force with 3 entries, expected 48 (3 x number of nodes)",
//    "Backward: the rollout's input 0: activation has 3 entries, expected 2 (one per muscle)";
//  - made with the simulator's current materials, time step and method
//    (SettingsMismatch): "Backward: the rollout was made with another time
//    step (0.01 s) than the simulator's current one (0.02 s)";
//  - with frictional contact (implicit methods), one report per step: "Backward: a rollout with frictional contact
//    needs its step reports (active sets)".
void CheckRolloutForDerivatives(const SimulatorImpl& sim, const Rollout& rollout, const std::string& caller);

// The same for a checkpointed rollout (checkpointed_rollout.h): valid
// checkpoint options, the initial, final and checkpoint states of 3n finite
// entries ("Backward: the checkpointed rollout's checkpoint 0 has v with 5
// entries, expected 48 finite ones (3 x number of nodes)"), the checkpoints
// SimulateCheckpointed keeps ("Backward: the checkpointed rollout's
// checkpoints are not those SimulateCheckpointed keeps for its number of
// steps and checkpoint options"), the inputs and settings as above.
void CheckCheckpointedRollout(const SimulatorImpl& sim, const CheckpointedRollout& rollout, const std::string& caller);

// Throws InvalidInputError unless `loss` has steps + 1 entries in dx and in
// dv ("Backward: the loss gradient must have 3 entries in dx and dv (got 2
// and 3)"), each empty or of n finite entries ("loss.dv has 4 entries,
// expected 135 (3 x number of nodes)", "loss.dx has a non-finite entry").
void CheckLossGradient(const LossGradient& loss, int steps, int n);

}  // namespace diffpd::internal
