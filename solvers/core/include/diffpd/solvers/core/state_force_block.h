// Parameters of the scene's state forces (state_forces.h, contact.h) as
// optimisation parameters: linear damping, the hydrodynamic coefficients and
// flow velocity, and the Coulomb coefficient of a penalty contact, each
// divided by a scale (parameter = value / scale).
//
// A change of these values rebuilds the rollout function's simulator (its
// precomputation and PD factor) before the next rollout. Both derivative
// modes cover them (forward mode through InputDirection::state_forces).
#pragma once

#include <string>
#include <vector>

#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::solvers {

enum class StateForceField {
  kLinearDamping,   // Scene::linear_damping, 1/s
  kFluidDensity,    // Hydrodynamics::fluid_density, kg/m^3
  kDragTangential,  // Hydrodynamics::drag_tangential
  kDragNormal,      // Hydrodynamics::drag_normal
  kThrust,          // Hydrodynamics::thrust
  kFlowVelocityX,   // Hydrodynamics::flow_velocity, m/s
  kFlowVelocityY,
  kFlowVelocityZ,
  kPenaltyFriction,  // Scene::penalty_contacts[contact].friction
};
// "linear_damping", "fluid_density", "drag_tangential", "drag_normal",
// "thrust", "flow_velocity_x", "flow_velocity_y", "flow_velocity_z",
// "penalty_friction".
const char* ToString(StateForceField field);

class StateForceBlock : public ParameterBlock {
 public:
  struct Entry {
    // Implicit from a field, scale 1.
    Entry(StateForceField field = StateForceField::kLinearDamping, double scale = 1, int contact = 0)
        : field(field), scale(scale), contact(contact) {}
    StateForceField field;
    double scale;  // units of the value per parameter unit, finite and > 0
    int contact;   // kPenaltyFriction: index into Scene::penalty_contacts
  };
  // Starting values: `scene`'s values / scale. Throws InvalidInputError:
  //   "state_forces: no parameter",
  //   "state_forces: entry 0: scale = -1 is invalid: must be finite and > 0",
  //   "state_forces: entry 0: linear_damping is not declared by the scene",
  //   "state_forces: entry 1: penalty contact 3 is out of range [0, 1)",
  //   "state_forces: entry 1: penalty contact 0 has friction 0: a fitted friction must start > 0",
  //   "state_forces: entry 2 lists thrust again".
  StateForceBlock(std::vector<Entry> entries, const Scene& scene);
  std::string name() const override { return "state_forces"; }
  const std::vector<Entry>& entries() const { return entries_; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const RolloutSetup& setup,
                   InputDirection* direction) const override;

 private:
  std::vector<Entry> entries_;
};

}  // namespace diffpd::solvers
