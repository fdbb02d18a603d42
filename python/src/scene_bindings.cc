// Scenes and what they declare (diffpd/scene.h, muscle.h, muscle_strip.h,
// contact.h, state_forces.h, quad_hydrodynamics.h). Eigen members are views of
// the scene's memory; std::vector members (dofs, element lists, muscles, ...)
// are copied on access: assign a new list to change one, e.g.
// scene.muscles = scene.muscles + [muscle].
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "diffpd/contact.h"
#include "diffpd/error.h"
#include "diffpd/muscle.h"
#include "diffpd/muscle_strip.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/wetted_quads.h"
#include "diffpd/scene.h"
#include "diffpd/state_forces.h"

namespace py = pybind11;
using namespace py::literals;

namespace diffpd::python {

void BindScene(py::module_& m) {
  py::class_<DirichletBoundary> dirichlet(m, "DirichletBoundary",
                                          "Prescribed DoFs (d = 3 node + axis, strictly increasing) and values (m).");
  dirichlet.def(py::init<>()).def_readwrite("dofs", &DirichletBoundary::dofs);
  EigenMember(dirichlet, "values", &DirichletBoundary::values, "prescribed positions (m), one per DoF; a view");

  py::class_<MaterialRegion>(m, "MaterialRegion", "Elements with a material of their own.")
      .def(py::init([](std::vector<int> elements, MaterialParameters material) {
             return MaterialRegion{std::move(elements), material};
           }),
           "elements"_a = std::vector<int>{}, "material"_a = MaterialParameters{})
      .def_readwrite("elements", &MaterialRegion::elements)
      .def_readwrite("material", &MaterialRegion::material);

  py::class_<Muscle>(m, "Muscle", "A muscle actuator over elements with rest fibre directions (diffpd/muscle.h).")
      .def(py::init([](std::vector<int> elements, std::vector<Vec3> fibers, double stiffness) {
             return Muscle{std::move(elements), std::move(fibers), stiffness};
           }),
           "elements"_a = std::vector<int>{}, "fibers"_a = std::vector<Vec3>{}, "stiffness"_a = 1e6)
      .def_readwrite("elements", &Muscle::elements)
      .def_readwrite("fibers", &Muscle::fibers)
      .def_readwrite("stiffness", &Muscle::stiffness);
  py::class_<MuscleStrip>(m, "MuscleStrip", "A chain of elements, root to tip, made into muscles (muscle_strip.h).")
      .def(py::init([](std::vector<int> elements, const Vec3& fiber, double stiffness) {
             return MuscleStrip{std::move(elements), fiber, stiffness};
           }),
           "elements"_a = std::vector<int>{}, "fiber"_a = Vec3(Vec3::UnitX()), "stiffness"_a = 1e5)
      .def_readwrite("elements", &MuscleStrip::elements)
      .def_readwrite("fiber", &MuscleStrip::fiber)
      .def_readwrite("stiffness", &MuscleStrip::stiffness);

  py::class_<ContactSurface> surface(m, "ContactSurface", "A plane, sphere or height field (diffpd/contact.h).");
  py::enum_<ContactSurface::Kind>(surface, "Kind")
      .value("PLANE", ContactSurface::Kind::kPlane)
      .value("SPHERE", ContactSurface::Kind::kSphere)
      .value("HEIGHT_FIELD", ContactSurface::Kind::kHeightField);
  surface.def(py::init<>())
      .def_readwrite("kind", &ContactSurface::kind)
      .def_readwrite("normal", &ContactSurface::normal)
      .def_readwrite("offset", &ContactSurface::offset)
      .def_readwrite("center", &ContactSurface::center)
      .def_readwrite("radius", &ContactSurface::radius)
      .def_static("plane", &ContactSurface::Plane, "normal"_a, "offset"_a)
      .def_static("sphere", &ContactSurface::Sphere, "center"_a, "radius"_a)
      .def_static("height_field", &ContactSurface::HeightField, "height"_a, "height_gradient"_a,
                  "height(x, y) -> float and height_gradient(x, y) -> (dh/dx, dh/dy), Python callables.")
      .def("gap", &ContactSurface::Gap, "x"_a)
      .def("gap_gradient", &ContactSurface::GapGradient, "x"_a)
      .def("project", &ContactSurface::Project, "x"_a)
      .def("project_jacobian", &ContactSurface::ProjectJacobian, "x"_a);
  py::enum_<ContactLinearSolve>(m, "ContactLinearSolve")
      .value("WOODBURY", ContactLinearSolve::kWoodbury)
      .value("REFACTORIZE", ContactLinearSolve::kRefactorize);
  py::class_<FrictionalContact>(m, "FrictionalContact", "A surface and its candidate nodes.")
      .def(py::init([](ContactSurface surface, std::vector<int> nodes) {
             return FrictionalContact{std::move(surface), std::move(nodes)};
           }),
           "surface"_a = ContactSurface{}, "nodes"_a = std::vector<int>{})
      .def_readwrite("surface", &FrictionalContact::surface)
      .def_readwrite("nodes", &FrictionalContact::nodes);
  py::class_<FrictionalContactOptions>(m, "FrictionalContactOptions")
      .def(py::init<>())
      .def_readwrite("max_passes", &FrictionalContactOptions::max_passes)
      .def_readwrite("penetration_tolerance", &FrictionalContactOptions::penetration_tolerance)
      .def_readwrite("screening_rel_tolerance", &FrictionalContactOptions::screening_rel_tolerance)
      .def_readwrite("pd_linear_solve", &FrictionalContactOptions::pd_linear_solve);
  py::class_<PenaltyContact>(m, "PenaltyContact", "A penalty half-space n . x >= offset with friction.")
      .def(py::init<>())
      .def_readwrite("normal", &PenaltyContact::normal)
      .def_readwrite("offset", &PenaltyContact::offset)
      .def_readwrite("nodes", &PenaltyContact::nodes)
      .def_readwrite("stiffness", &PenaltyContact::stiffness)
      .def_readwrite("friction", &PenaltyContact::friction)
      .def_readwrite("friction_velocity", &PenaltyContact::friction_velocity);

  py::class_<Hydrodynamics> hydro(m, "Hydrodynamics", "Drag and thrust on wetted triangles (state_forces.h).");
  hydro.def(py::init<>());
  EigenMember(hydro, "triangles", &Hydrodynamics::triangles, "3 x t node indices (int32); a view");
  hydro.def_readwrite("fluid_density", &Hydrodynamics::fluid_density)
      .def_readwrite("drag_tangential", &Hydrodynamics::drag_tangential)
      .def_readwrite("drag_normal", &Hydrodynamics::drag_normal)
      .def_readwrite("thrust", &Hydrodynamics::thrust)
      .def_readwrite("flow_velocity", &Hydrodynamics::flow_velocity);
  py::class_<QuadHydrodynamics> quad(m, "QuadHydrodynamics", "Drag and thrust on one-sided quads (Bezier curves).");
  quad.def(py::init<>());
  EigenMember(quad, "quads", &QuadHydrodynamics::quads, "4 x F node indices (int32); a view");
  quad.def_readwrite("fluid_density", &QuadHydrodynamics::fluid_density)
      .def_readwrite("flow_velocity", &QuadHydrodynamics::flow_velocity)
      .def_readwrite("drag_curve", &QuadHydrodynamics::drag_curve)
      .def_readwrite("thrust_curve", &QuadHydrodynamics::thrust_curve);
  m.def(
      "wetted_quads",
      [](const QuadHydrodynamics& water, const VectorXd& x, const VectorXd& v) {
        const Eigen::Index nodes = x.size() / 3;
        if (x.size() % 3 != 0 || v.size() != x.size())
          throw InvalidInputError("wetted_quads: x and v must have the same length, a multiple of 3 (got " +
                                  std::to_string(x.size()) + " and " + std::to_string(v.size()) + ")");
        if (water.quads.size() > 0 && (water.quads.minCoeff() < 0 || water.quads.maxCoeff() >= nodes))
          throw InvalidInputError("wetted_quads: water.quads has node indices outside [0, " + std::to_string(nodes) +
                                  ") for x of " + std::to_string(x.size()) + " entries");
        const std::vector<char> wetted = WettedQuads(water, x, v);
        return std::vector<bool>(wetted.begin(), wetted.end());
      },
      "water"_a, "x"_a, "v"_a,
      "Per face of water.quads, whether the water meets it at positions x and velocities v (3n each).");
  py::class_<QuadHydrodynamicsGradient>(m, "QuadHydrodynamicsGradient")
      .def(py::init<>())
      .def_readwrite("fluid_density", &QuadHydrodynamicsGradient::fluid_density)
      .def_readwrite("flow_velocity", &QuadHydrodynamicsGradient::flow_velocity)
      .def_readwrite("drag_curve", &QuadHydrodynamicsGradient::drag_curve)
      .def_readwrite("thrust_curve", &QuadHydrodynamicsGradient::thrust_curve);
  py::class_<StateForceGradient>(m, "StateForceGradient", "Derivatives w.r.t. the declared state-force parameters.")
      .def(py::init<>())
      .def_readwrite("linear_damping", &StateForceGradient::linear_damping)
      .def_readwrite("fluid_density", &StateForceGradient::fluid_density)
      .def_readwrite("drag_tangential", &StateForceGradient::drag_tangential)
      .def_readwrite("drag_normal", &StateForceGradient::drag_normal)
      .def_readwrite("thrust", &StateForceGradient::thrust)
      .def_readwrite("flow_velocity", &StateForceGradient::flow_velocity)
      .def_readwrite("penalty_friction", &StateForceGradient::penalty_friction)
      .def_readwrite("quad_hydrodynamics", &StateForceGradient::quad_hydrodynamics);

  LibraryNames(py::enum_<MassLumping>(m, "MassLumping", "How a body's mass is spread over its nodes.")
                   .value("LUMPED", MassLumping::kLumped)
                   .value("EQUAL_NODES", MassLumping::kEqualNodes));
  py::class_<Scene>(m, "Scene", "What a simulation contains (diffpd/scene.h).")
      .def(py::init<>())
      .def(py::init([](Mesh mesh, MaterialParameters material) {
             Scene scene;
             scene.mesh = std::move(mesh);
             scene.material = material;
             return scene;
           }),
           "mesh"_a, "material"_a = MaterialParameters{})
      .def_readwrite("mesh", &Scene::mesh)
      .def_readwrite("material", &Scene::material)
      .def_readwrite("material_regions", &Scene::material_regions)
      .def_readwrite("energies", &Scene::energies)
      .def_readwrite("mass_lumping", &Scene::mass_lumping)
      .def_readwrite("gravity", &Scene::gravity, "m/s^2 (length 3) or None")
      .def_readwrite("dirichlet", &Scene::dirichlet)
      .def_readwrite("muscles", &Scene::muscles)
      .def_readwrite("frictional_contacts", &Scene::frictional_contacts)
      .def_readwrite("frictional_contact_options", &Scene::frictional_contact_options)
      .def_readwrite("penalty_contacts", &Scene::penalty_contacts)
      .def_readwrite("hydrodynamics", &Scene::hydrodynamics)
      .def_readwrite("quad_hydrodynamics", &Scene::quad_hydrodynamics)
      .def_readwrite("linear_damping", &Scene::linear_damping, "c (1/s) or None")
      .def("validate", &Scene::Validate, "Raises InvalidInputError naming the first problem.")
      .def(
          "fix_nodes", [](Scene& self, const std::vector<int>& nodes) { FixNodes(&self, nodes); }, "nodes"_a,
          "Fixes all three axes of the nodes at their rest positions.")
      .def(
          "fix_node_axes",
          [](Scene& self, const std::vector<int>& nodes, const std::vector<int>& axes) {
            FixNodeAxes(&self, nodes, axes);
          },
          "nodes"_a, "axes"_a, "Fixes the given axes (0 = x, 1 = y, 2 = z) of the nodes at rest positions.")
      .def(
          "add_muscle_strips",
          [](Scene& self, const std::vector<MuscleStrip>& strips) { return AddMuscleStrips(&self, strips); },
          "strips"_a, "Appends one muscle per strip element; returns each strip's muscle indices.");
}

}  // namespace diffpd::python
