// Closed-loop control: a policy that chooses every step's actions from the
// simulated state and its own memory, differentiated through the rollout.
//
// At step k = 0..K-1 of a closed-loop rollout (Simulator::Simulate with a
// controller), with m_0 = InitialMemory():
//
//   (u_k, m_{k+1}) = pi(k, x_k, v_k, m_k; theta),
//   (x_{k+1}, v_{k+1}) = step(x_k, v_k; u_k),
//
// u_k = (activation, external force) the step's action (StepInput), m_k the
// controller's memory (e.g. a delay line of past activations) and theta its
// parameters (e.g. a network's weights). Simulator::Backward with the
// controller adds pi's vector-Jacobian products to the state adjoint,
//
//   dL/dx_k += (du_k/dx_k)^T dL/du_k + (dm_{k+1}/dx_k)^T dL/dm_{k+1}  (and v_k alike),
//   dL/dm_k  = (du_k/dm_k)^T dL/du_k + (dm_{k+1}/dm_k)^T dL/dm_{k+1},
//   dL/dtheta = sum_k (du_k/dtheta)^T dL/du_k + (dm_{k+1}/dtheta)^T dL/dm_{k+1},
//
// and returns dL/dtheta and dL/dm_0 (RolloutGradient).
#pragma once

#include <memory>

#include "diffpd/rollout.h"
#include "diffpd/types.h"

namespace diffpd {

// One step's action, or the gradient of a loss w.r.t. it. Empty vectors mean
// none (zero gradient): activation has one entry per Scene::muscles entry
// (muscle.h; finite, any sign), external_force 3n entries (N).
struct ControlAction {
  VectorXd activation;
  VectorXd external_force;
};

// A differentiable policy. Implementations are deterministic functions of
// their arguments and parameters (no hidden state: the memory is explicit),
// so a rollout can be replayed and differentiated.
class Controller {
 public:
  virtual ~Controller() = default;
  // A copy with the same parameters (rollouts at other parameters keep their
  // own copies, solvers/core/controller_block.h).
  virtual std::unique_ptr<Controller> Clone() const = 0;

  // theta: the parameters (num_parameters() entries).
  virtual int num_parameters() const = 0;
  virtual VectorXd parameters() const = 0;
  // Throws InvalidInputError for a wrong size or a non-finite entry.
  virtual void SetParameters(const VectorXd& parameters) = 0;

  // Size of the memory m (0: a memoryless policy) and its value before the
  // first step.
  virtual int memory_size() const { return 0; }
  virtual VectorXd InitialMemory() const { return VectorXd::Zero(memory_size()); }

  // pi at step k: the action and the next memory (memory_size() entries)
  // from the state (x_k, v_k, 3n each) and the memory m_k.
  virtual void Act(int step, const State& state, const VectorXd& memory, ControlAction* action,
                   VectorXd* next_memory) const = 0;

  // Reverse mode of Act at the same arguments: given g_action = dL/du_k
  // (entries may be empty: zero) and g_next_memory = dL/dm_{k+1} (empty:
  // zero), adds (du_k/dx_k)^T g_action + (dm_{k+1}/dx_k)^T g_next_memory to
  // *gx (3n) and the same in v_k to *gv (3n), sets *g_memory = dL/dm_k
  // (memory_size() entries) and adds dL/dtheta to *g_parameters
  // (num_parameters() entries).
  virtual void ActVjp(int step, const State& state, const VectorXd& memory, const ControlAction& g_action,
                      const VectorXd& g_next_memory, VectorXd* gx, VectorXd* gv, VectorXd* g_memory,
                      VectorXd* g_parameters) const = 0;
};

}  // namespace diffpd
