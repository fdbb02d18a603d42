#include "solver/rollout_checks.h"

#include <sstream>

#include "diffpd/error.h"
#include "forces/activation_scope.h"

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
  for (size_t k = 0; k < steps; ++k) {
    CheckEntries(rollout.inputs[k].external_force, n, true, caller, "input", k, "external_force");
    try {
      CheckActivation(rollout.inputs[k].activation, sim.aux.num_muscles());
    } catch (const InvalidInputError& e) {
      throw InvalidInputError(caller + ": the rollout's input " + std::to_string(k) + ": " + e.what());
    }
  }
  if (!MadeWithCurrentSettings(sim, rollout))
    throw InvalidInputError(caller +
                            ": the rollout was made with another material, time step or method than the simulator's "
                            "current ones");
  const bool contact = !sim.scene.frictional_contacts.empty() && sim.options.method != Method::kSemiImplicit;
  if (contact && rollout.reports.size() != steps)
    throw InvalidInputError(caller + ": a rollout with frictional contact needs its step reports (active sets)");
}

}  // namespace diffpd::internal
