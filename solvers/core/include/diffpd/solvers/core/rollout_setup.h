// What one rollout is made from: the initial state, the per-step inputs, the
// materials and the state-force parameters. Parameter blocks
// (parameter_block.h) write their values into it; RolloutFunction
// (rollout_function.h) simulates it.
#pragma once

#include <memory>
#include <vector>

#include "diffpd/controller.h"
#include "diffpd/material.h"
#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/types.h"

namespace diffpd::solvers {

// The parameters of a scene's state forces (state_forces.h, contact.h) that a
// rollout may vary. Only the terms the scene declares act; the others are
// zero here and stay undeclared.
struct StateForceParameters {
  double linear_damping = 0;  // c, 1/s (Scene::linear_damping)
  // Scene::hydrodynamics: fluid density (kg/m^3), drag and thrust
  // coefficients, flow velocity (m/s).
  double fluid_density = 0;
  double drag_tangential = 0;
  double drag_normal = 0;
  double thrust = 0;
  Vec3 flow_velocity = Vec3::Zero();
  // Coulomb coefficient mu per Scene::penalty_contacts entry, in order. A
  // contact whose mu is 0 declares no friction force.
  std::vector<double> penalty_friction;

  // The values `scene` declares.
  static StateForceParameters Of(const Scene& scene);
  // Writes the values into the terms *scene declares (sizes must match the
  // scene's penalty contacts).
  void ApplyTo(Scene* scene) const;
  bool operator==(const StateForceParameters& other) const;
  bool operator!=(const StateForceParameters& other) const { return !(*this == other); }
};

struct RolloutSetup {
  State initial;                  // x_0 (m) and v_0 (m/s), 3n each
  std::vector<StepInput> inputs;  // K steps; empty fields mean "none"
  MaterialParameters material;    // Scene::material
  // One per Scene::material_regions entry, in order.
  std::vector<MaterialParameters> region_materials;
  StateForceParameters state_forces;
  // Closed loop (controller_block.h): the controller that chooses every
  // step's action from the state; its actions replace `inputs`. nullptr:
  // open loop.
  std::shared_ptr<const Controller> controller;
};

}  // namespace diffpd::solvers
