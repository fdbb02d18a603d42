#include "solver/rollout_checks.h"

#include <sstream>

#include "diffpd/error.h"
#include "forces/activation_scope.h"
#include "forces/quad_hydrodynamic_force.h"
#include "solver/checkpoint_schedule.h"

namespace diffpd::internal {
namespace {

// "<caller>: the rollout's <item> <k> has <name> with ..." unless v has n
// finite entries (or is empty where allowed).
void CheckEntries(const VectorXd& v, int n, bool allow_empty, const std::string& caller, const char* item, size_t k,
                  const char* name) {
  if (allow_empty && v.size() == 0) return;
  std::ostringstream msg;
  msg << caller << ": the rollout's " << item << " " << k << " has ";
  if (v.size() != n) {
    msg << name << " with " << v.size() << " entries, expected " << n << " (3 x number of nodes)";
    throw InvalidInputError(msg.str());
  }
  if (!v.allFinite()) {
    msg << "a non-finite entry in " << name;
    throw InvalidInputError(msg.str());
  }
}

// "<caller>: the checkpointed rollout's <what> has x with ..." unless s has
// 3n finite entries in x and in v.
void CheckState(const State& s, int n, const std::string& caller, const std::string& what) {
  for (const VectorXd* v : {&s.x, &s.v})
    if (v->size() != n || !v->allFinite()) {
      std::ostringstream msg;
      msg << caller << ": the checkpointed rollout's " << what << " has " << (v == &s.x ? "x" : "v") << " with "
          << v->size() << " entries, expected " << n << " finite ones (3 x number of nodes)";
      throw InvalidInputError(msg.str());
    }
}

// Every input's external force, activation and held quad faces, then the settings the
// rollout was made with (the rules of CheckRolloutForDerivatives).
void CheckInputsAndSettings(const SimulatorImpl& sim, const std::vector<StepInput>& inputs,
                            const MaterialParameters& material, const std::vector<MaterialParameters>& region_materials,
                            const SolverOptions& options, const std::string& caller) {
  const int n = sim.num_dofs();
  for (size_t k = 0; k < inputs.size(); ++k) {
    CheckEntries(inputs[k].external_force, n, true, caller, "input", k, "external_force");
    try {
      CheckActivation(inputs[k].activation, sim.aux.num_muscles());
      CheckWettedQuads(inputs[k].wetted_quads, sim.scene.quad_hydrodynamics);
    } catch (const InvalidInputError& e) {
      throw InvalidInputError(caller + ": the rollout's input " + std::to_string(k) + ": " + e.what());
    }
  }
  const std::string mismatch = SettingsMismatch(sim, material, region_materials, options);
  if (!mismatch.empty()) throw InvalidInputError(caller + ": the rollout was made with " + mismatch);
}

}  // namespace

void CheckRolloutForDerivatives(const SimulatorImpl& sim, const Rollout& rollout, const std::string& caller) {
  const int n = sim.num_dofs();
  const size_t steps = rollout.inputs.size();
  if (rollout.states.size() != steps + 1) {
    std::ostringstream msg;
    msg << caller << ": the rollout has " << rollout.states.size() << " states for " << steps
        << " inputs (needs one more state than inputs)";
    throw InvalidInputError(msg.str());
  }
  for (size_t k = 0; k < rollout.states.size(); ++k) {
    CheckEntries(rollout.states[k].x, n, false, caller, "state", k, "x");
    CheckEntries(rollout.states[k].v, n, false, caller, "state", k, "v");
  }
  CheckInputsAndSettings(sim, rollout.inputs, rollout.material, rollout.region_materials, rollout.options, caller);
  const bool contact = !sim.scene.frictional_contacts.empty() && sim.options.method != Method::kSemiImplicit;
  if (contact && rollout.reports.size() != steps)
    throw InvalidInputError(caller + ": a rollout with frictional contact needs its step reports (active sets)");
}

void CheckCheckpointedRollout(const SimulatorImpl& sim, const CheckpointedRollout& rollout, const std::string& caller) {
  const int n = sim.num_dofs();
  const int steps = rollout.num_steps();
  rollout.checkpoint_options.Validate();
  CheckState(rollout.initial, n, caller, "initial state");
  CheckState(rollout.final, n, caller, "final state");
  if (rollout.checkpoint_steps != FirstDescentSteps(steps, rollout.checkpoint_options.num_checkpoints) ||
      rollout.checkpoints.size() != rollout.checkpoint_steps.size() ||
      rollout.checkpoint_reports.size() != rollout.checkpoint_steps.size())
    throw InvalidInputError(caller +
                            ": the checkpointed rollout's checkpoints are not those SimulateCheckpointed keeps for its "
                            "number of steps and checkpoint options");
  if (rollout.options.svd_warm_start)
    throw InvalidInputError(caller +
                            ": the checkpointed rollout's options have svd_warm_start = true; its steps cannot be "
                            "recomputed bit for bit (SimulateCheckpointed sets it false)");
  for (size_t c = 0; c < rollout.checkpoints.size(); ++c)
    CheckState(rollout.checkpoints[c], n, caller, "checkpoint " + std::to_string(c));
  CheckInputsAndSettings(sim, rollout.inputs, rollout.material, rollout.region_materials, rollout.options, caller);
}

void CheckLossGradient(const LossGradient& loss, int steps, int n) {
  if (static_cast<int>(loss.dx.size()) != steps + 1 || static_cast<int>(loss.dv.size()) != steps + 1) {
    std::ostringstream msg;
    msg << "Backward: the loss gradient must have " << steps + 1 << " entries in dx and dv (got " << loss.dx.size()
        << " and " << loss.dv.size() << ")";
    throw InvalidInputError(msg.str());
  }
  for (int k = 0; k <= steps; ++k)
    for (const VectorXd* g : {&loss.dx[k], &loss.dv[k]}) {
      const char* name = g == &loss.dx[k] ? "loss.dx" : "loss.dv";
      if (g->size() == 0) continue;
      if (g->size() != n) {
        std::ostringstream msg;
        msg << name << " has " << g->size() << " entries, expected " << n << " (3 x number of nodes)";
        throw InvalidInputError(msg.str());
      }
      if (!g->allFinite()) throw InvalidInputError(std::string(name) + " has a non-finite entry");
    }
}

}  // namespace diffpd::internal
