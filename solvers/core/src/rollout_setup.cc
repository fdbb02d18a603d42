#include "diffpd/solvers/core/rollout_setup.h"

#include "diffpd/error.h"

namespace diffpd::solvers {

StateForceParameters StateForceParameters::Of(const Scene& scene) {
  StateForceParameters p;
  if (scene.linear_damping) p.linear_damping = *scene.linear_damping;
  if (scene.hydrodynamics) {
    const Hydrodynamics& h = *scene.hydrodynamics;
    p.fluid_density = h.fluid_density;
    p.drag_tangential = h.drag_tangential;
    p.drag_normal = h.drag_normal;
    p.thrust = h.thrust;
    p.flow_velocity = h.flow_velocity;
  }
  for (const PenaltyContact& c : scene.penalty_contacts) p.penalty_friction.push_back(c.friction);
  return p;
}

void StateForceParameters::ApplyTo(Scene* scene) const {
  DIFFPD_CHECK(penalty_friction.size() == scene->penalty_contacts.size(),
               "state-force parameters for " << penalty_friction.size() << " penalty contacts, the scene has "
                                             << scene->penalty_contacts.size());
  if (scene->linear_damping) scene->linear_damping = linear_damping;
  if (scene->hydrodynamics) {
    Hydrodynamics& h = *scene->hydrodynamics;
    h.fluid_density = fluid_density;
    h.drag_tangential = drag_tangential;
    h.drag_normal = drag_normal;
    h.thrust = thrust;
    h.flow_velocity = flow_velocity;
  }
  for (size_t c = 0; c < penalty_friction.size(); ++c) scene->penalty_contacts[c].friction = penalty_friction[c];
}

bool StateForceParameters::operator==(const StateForceParameters& o) const {
  return linear_damping == o.linear_damping && fluid_density == o.fluid_density &&
         drag_tangential == o.drag_tangential && drag_normal == o.drag_normal && thrust == o.thrust &&
         flow_velocity == o.flow_velocity && penalty_friction == o.penalty_friction;
}

}  // namespace diffpd::solvers
