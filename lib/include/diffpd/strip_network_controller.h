// A neural-network controller of muscle strips (controller.h), after the
// original DiffPD swimmers' controller: a multilayer perceptron (mlp.h) maps
// an observation of the state to channel values w in (-1, 1) (tanh output),
// each strip takes the positive or the negative part of one channel as its
// new contraction, and a per-element delay line (muscle_strip.h) carries the
// contractions along the strips.
//
// Observation (3 + 6 P values) of reference node r and tracked nodes p_1..p_P:
//
//   o = (v_r, x_{p_1} - x_r, ..., x_{p_P} - x_r, v_{p_1}, ..., v_{p_P}),
//
// velocities in m/s, positions in m. Strip s driven by channel c_s with sign
// sigma_s = +1 or -1 contracts by u_s = max(sigma_s w_{c_s}, 0) (derivative
// 0 where sigma_s w_{c_s} = 0). The memory is the delay line's (contractions,
// zero at the start), the parameters the network's.
#pragma once

#include <memory>

#include <vector>

#include "diffpd/controller.h"
#include "diffpd/mlp.h"
#include "diffpd/muscle_strip.h"
#include "diffpd/strip_drive.h"

namespace diffpd {

// What the network sees: node indices (not DoFs).
struct NodeObservation {
  int reference_node = 0;
  std::vector<int> nodes;
  int size() const { return 3 + 6 * static_cast<int>(nodes.size()); }
};

class StripNetworkController : public Controller {
 public:
  // drives: one per strip of the delay line. Throws InvalidInputError when
  // the network's inputs differ from the observation's size ("StripNetworkController:
  // the network has 240 inputs, the observation 243 values"), for a node
  // index out of [0, num_nodes), a drive per strip missing, a channel out of
  // range or a sign other than +1 or -1.
  StripNetworkController(Mlp network, NodeObservation observation, MuscleDelayLine delay_line,
                         std::vector<StripDrive> drives, int num_nodes);

  const Mlp& network() const { return network_; }
  const NodeObservation& observation() const { return observation_; }
  const MuscleDelayLine& delay_line() const { return delay_line_; }
  // The observation o of a state (observation().size() values).
  VectorXd Observe(const State& state) const;

  std::unique_ptr<Controller> Clone() const override { return std::make_unique<StripNetworkController>(*this); }
  int num_parameters() const override { return network_.num_parameters(); }
  VectorXd parameters() const override { return network_.parameters(); }
  void SetParameters(const VectorXd& parameters) override { network_.SetParameters(parameters); }
  int memory_size() const override { return delay_line_.memory_size(); }
  void Act(int step, const State& state, const VectorXd& memory, ControlAction* action,
           VectorXd* next_memory) const override;
  void ActVjp(int step, const State& state, const VectorXd& memory, const ControlAction& g_action,
              const VectorXd& g_next_memory, VectorXd* gx, VectorXd* gv, VectorXd* g_memory,
              VectorXd* g_parameters) const override;

 private:
  Mlp network_;
  NodeObservation observation_;
  MuscleDelayLine delay_line_;
  std::vector<StripDrive> drives_;
  int num_nodes_;
};

}  // namespace diffpd
