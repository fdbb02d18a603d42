#include "diffpd/strip_network_controller.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd {

StripNetworkController::StripNetworkController(Mlp network, NodeObservation observation, MuscleDelayLine delay_line,
                                               std::vector<StripDrive> drives, int num_nodes)
    : network_(std::move(network)),
      observation_(std::move(observation)),
      delay_line_(std::move(delay_line)),
      drives_(std::move(drives)),
      num_nodes_(num_nodes) {
  std::ostringstream msg;
  msg << "StripNetworkController: ";
  if (network_.num_inputs() != observation_.size()) {
    msg << "the network has " << network_.num_inputs() << " inputs, the observation " << observation_.size()
        << " values";
    throw InvalidInputError(msg.str());
  }
  auto check_node = [&](int node, const std::string& what) {
    if (node < 0 || node >= num_nodes) {
      msg << what << " = " << node << " is out of range [0, " << num_nodes << ") (no such node)";
      throw InvalidInputError(msg.str());
    }
  };
  check_node(observation_.reference_node, "observation.reference_node");
  for (size_t p = 0; p < observation_.nodes.size(); ++p)
    check_node(observation_.nodes[p], "observation.nodes[" + std::to_string(p) + "]");
  CheckStripDrives(drives_, delay_line_.num_strips(), network_.num_outputs(), "StripNetworkController",
                   "the network's outputs");
}

VectorXd StripNetworkController::Observe(const State& state) const {
  const int p = static_cast<int>(observation_.nodes.size());
  const int r = observation_.reference_node;
  VectorXd o(observation_.size());
  o.head<3>() = state.v.segment<3>(3 * r);
  for (int k = 0; k < p; ++k) {
    const int i = observation_.nodes[k];
    o.segment<3>(3 + 3 * k) = state.x.segment<3>(3 * i) - state.x.segment<3>(3 * r);
    o.segment<3>(3 + 3 * p + 3 * k) = state.v.segment<3>(3 * i);
  }
  return o;
}

void StripNetworkController::Act(int step, const State& state, const VectorXd& memory, ControlAction* action,
                                 VectorXd* next_memory) const {
  const VectorXd channels = network_.Evaluate(Observe(state));
  action->external_force.resize(0);
  delay_line_.Advance(memory, StripContractions(drives_, channels), next_memory, &action->activation);
}

void StripNetworkController::ActVjp(int step, const State& state, const VectorXd& memory, const ControlAction& g_action,
                                    const VectorXd& g_next_memory, VectorXd* gx, VectorXd* gv, VectorXd* g_memory,
                                    VectorXd* g_parameters) const {
  MlpTape tape;
  const VectorXd channels = network_.Forward(Observe(state), &tape);
  VectorXd g_u;
  delay_line_.AdvanceVjp(g_action.activation, g_next_memory, g_memory, &g_u);
  VectorXd g_channels = VectorXd::Zero(channels.size());
  AddStripContractionsVjp(drives_, channels, g_u, &g_channels);
  VectorXd g_obs;
  network_.Backward(tape, g_channels, &g_obs, g_parameters);
  const int p = static_cast<int>(observation_.nodes.size());
  const int r = observation_.reference_node;
  gv->segment<3>(3 * r) += g_obs.head<3>();
  for (int k = 0; k < p; ++k) {
    const int i = observation_.nodes[k];
    const Vec3 g_rel = g_obs.segment<3>(3 + 3 * k);
    gx->segment<3>(3 * i) += g_rel;
    gx->segment<3>(3 * r) -= g_rel;
    gv->segment<3>(3 * i) += g_obs.segment<3>(3 + 3 * p + 3 * k);
  }
}

}  // namespace diffpd
