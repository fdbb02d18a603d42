// Bad declarations of muscles, contact and state forces are rejected by
// Scene::Validate (and so by the Simulator) with messages naming the input,
// its value and the valid range.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "diffpd/error.h"
#include "diffpd/scene.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

void ExpectMessage(const std::function<void(Scene*)>& spoil, const std::string& message) {
  Scene scene = testing::SmallBeamScene();
  Muscle m;
  m.elements = {0, 3};
  m.fibers = {Vec3(1, 0, 0)};
  scene.muscles = {m};
  FrictionalContact c;
  c.surface = ContactSurface::Plane(Vec3(0, 0, 1), -0.1);
  c.nodes = {40, 41};
  scene.frictional_contacts = {c};
  PenaltyContact p;
  p.nodes = {42};
  scene.penalty_contacts = {p};
  Hydrodynamics hydro;
  hydro.triangles = BoundaryTriangles(scene.mesh);
  scene.hydrodynamics = hydro;
  scene.linear_damping = 0.1;
  scene.Validate();  // the unspoilt scene is valid
  spoil(&scene);
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError, message);
}

TEST(OptionalTermsValidationTest, MuscleErrorsNameTheMuscleAndTheValue) {
  ExpectMessage([](Scene* s) { s->muscles[0].fibers = {Vec3::Zero()}; },
                "scene: muscles[0].fibers[0] = (0, 0, 0) is invalid: must be finite with non-zero length");
  ExpectMessage([](Scene* s) { s->muscles[0].elements[1] = 16; },
                "scene: muscles[0].elements[1] = 16 is out of range [0, 16) (no such element)");
  ExpectMessage([](Scene* s) { s->muscles[0].elements.clear(); }, "scene: muscles[0] has no elements");
  ExpectMessage(
      [](Scene* s) {
        s->muscles[0].fibers = {Vec3(1, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
      },
      "scene: muscles[0] has 3 fibre directions for 2 elements (need one per element or a single shared one)");
  ExpectMessage([](Scene* s) { s->muscles[0].stiffness = -1; },
                "scene: muscles[0].stiffness = -1 is invalid: must be finite and > 0 (Pa)");
}

TEST(OptionalTermsValidationTest, StateForceParametersMustBeFinite) {
  ExpectMessage([](Scene* s) { s->hydrodynamics->fluid_density = std::nan(""); },
                "scene: hydrodynamics.fluid_density = nan is invalid: must be finite and >= 0 (kg/m^3)");
  ExpectMessage([](Scene* s) { s->hydrodynamics->drag_normal = INFINITY; },
                "scene: hydrodynamics.drag_normal = inf is invalid: must be finite and >= 0");
  ExpectMessage([](Scene* s) { s->hydrodynamics->drag_tangential = -0.1; },
                "scene: hydrodynamics.drag_tangential = -0.1 is invalid: must be finite and >= 0");
  ExpectMessage([](Scene* s) { s->hydrodynamics->thrust = std::nan(""); },
                "scene: hydrodynamics.thrust = nan is invalid: must be finite");
  ExpectMessage([](Scene* s) { s->hydrodynamics->flow_velocity(1) = INFINITY; },
                "scene: hydrodynamics.flow_velocity = (0, inf, 0) is invalid: must be finite (m/s)");
  ExpectMessage([](Scene* s) { s->hydrodynamics->triangles(2, 5) = 99; },
                "scene: hydrodynamics.triangles(2, 5) = 99 is out of range [0, 45) (no such node)");
  ExpectMessage([](Scene* s) { s->linear_damping = -2; },
                "scene: linear_damping = -2 is invalid: must be finite and >= 0 (1/s)");
}

TEST(OptionalTermsValidationTest, ContactErrorsNameTheContactAndTheValue) {
  ExpectMessage(
      [](Scene* s) { s->frictional_contacts[0].surface.normal = Vec3::Zero(); },
      "scene: frictional_contacts[0].surface.normal = (0, 0, 0) is invalid: must be finite with non-zero length");
  ExpectMessage([](Scene* s) { s->frictional_contacts[0].surface = ContactSurface::Sphere(Vec3::Zero(), 0.0); },
                "scene: frictional_contacts[0].surface.radius = 0 is invalid: must be finite and > 0 (m)");
  ExpectMessage([](Scene* s) { s->frictional_contacts[0].surface = ContactSurface::HeightField(nullptr, nullptr); },
                "scene: frictional_contacts[0].surface: a height field needs both height and height_gradient");
  ExpectMessage([](Scene* s) { s->frictional_contacts[0].nodes.push_back(45); },
                "scene: frictional_contacts[0].nodes[2] = 45 is out of range [0, 45) (no such node)");
  ExpectMessage([](Scene* s) { s->frictional_contacts.push_back(s->frictional_contacts[0]); },
                "scene: node 40 is a candidate of frictional_contacts[0] and frictional_contacts[1] (a node may be a "
                "frictional contact candidate once)");
  ExpectMessage([](Scene* s) { s->frictional_contacts[0].nodes.push_back(0); },
                "scene: frictional_contacts[0].nodes[2] = 0 has a Dirichlet DoF; frictional contact candidates must be "
                "free");
  ExpectMessage([](Scene* s) { s->frictional_contacts[0].surface.kind = static_cast<ContactSurface::Kind>(7); },
                "scene: frictional_contacts[0].surface.kind = 7 is invalid: must be kPlane (0), kSphere (1) or "
                "kHeightField (2)");
  ExpectMessage([](Scene* s) { s->frictional_contact_options.pd_linear_solve = static_cast<ContactLinearSolve>(5); },
                "scene: frictional_contact_options.pd_linear_solve = 5 is invalid: must be kWoodbury (0) or "
                "kRefactorize (1)");
  ExpectMessage([](Scene* s) { s->frictional_contact_options.max_passes = 0; },
                "scene: frictional_contact_options.max_passes = 0 is invalid: must be >= 1");
  ExpectMessage(
      [](Scene* s) { s->frictional_contact_options.screening_rel_tolerance = 1; },
      "scene: frictional_contact_options.screening_rel_tolerance = 1 is invalid: must be finite and in [0, 1)");
  ExpectMessage([](Scene* s) { s->frictional_contact_options.max_energy_gain = -1; },
                "scene: frictional_contact_options.max_energy_gain = -1 is invalid: must be >= 0 (infinity: no check)");
  ExpectMessage(
      [](Scene* s) { s->frictional_contact_options.max_energy_gain = std::nan(""); },
      "scene: frictional_contact_options.max_energy_gain = nan is invalid: must be >= 0 (infinity: no check)");
  ExpectMessage([](Scene* s) { s->frictional_contact_options.screening_rel_tolerance = std::nan(""); },
                "scene: frictional_contact_options.screening_rel_tolerance = nan is invalid: must be finite and in [0, "
                "1)");
  ExpectMessage([](Scene* s) { s->penalty_contacts[0].stiffness = 0; },
                "scene: penalty_contacts[0].stiffness = 0 is invalid: must be finite and > 0 (N/m)");
  ExpectMessage([](Scene* s) { s->penalty_contacts[0].friction = std::nan(""); },
                "scene: penalty_contacts[0].friction = nan is invalid: must be finite and >= 0");
}

}  // namespace
}  // namespace diffpd
