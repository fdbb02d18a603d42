#include "forces/optional_terms_validation.h"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "diffpd/error.h"

namespace diffpd::internal {
namespace {

std::string Format(const Vec3& v) {
  std::ostringstream s;
  s << "(" << v(0) << ", " << v(1) << ", " << v(2) << ")";
  return s.str();
}

[[noreturn]] void Invalid(const std::string& name, const std::string& value, const std::string& range) {
  throw InvalidInputError("scene: " + name + " = " + value + " is invalid: must be " + range);
}

std::string Str(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void CheckPositive(const std::string& name, double v, const char* unit) {
  if (!(std::isfinite(v) && v > 0)) Invalid(name, Str(v), std::string("finite and > 0 (") + unit + ")");
}

void CheckNonNegative(const std::string& name, double v, const char* unit) {
  if (!(std::isfinite(v) && v >= 0)) Invalid(name, Str(v), std::string("finite and >= 0") + unit);
}

void CheckFiniteScalar(const std::string& name, double v, const char* unit) {
  if (!std::isfinite(v)) Invalid(name, Str(v), std::string("finite") + unit);
}

void CheckDirection(const std::string& name, const Vec3& v) {
  if (!(v.allFinite() && v.norm() > 0)) Invalid(name, Format(v), "finite with non-zero length");
}

void CheckNode(const std::string& name, int i, int n) {
  if (i < 0 || i >= n) {
    std::ostringstream s;
    s << "scene: " << name << " = " << i << " is out of range [0, " << n << ") (no such node)";
    throw InvalidInputError(s.str());
  }
}

std::string Indexed(const std::string& base, size_t k) { return base + "[" + std::to_string(k) + "]"; }

void ValidateMuscles(const Scene& scene) {
  const int m = scene.mesh.num_elements();
  for (size_t j = 0; j < scene.muscles.size(); ++j) {
    const Muscle& muscle = scene.muscles[j];
    const std::string name = Indexed("muscles", j);
    if (muscle.elements.empty()) throw InvalidInputError("scene: " + name + " has no elements");
    for (size_t t = 0; t < muscle.elements.size(); ++t) {
      const int e = muscle.elements[t];
      if (e < 0 || e >= m) {
        std::ostringstream s;
        s << "scene: " << Indexed(name + ".elements", t) << " = " << e << " is out of range [0, " << m
          << ") (no such element)";
        throw InvalidInputError(s.str());
      }
    }
    if (muscle.fibers.size() != 1 && muscle.fibers.size() != muscle.elements.size()) {
      std::ostringstream s;
      s << "scene: " << name << " has " << muscle.fibers.size() << " fibre directions for " << muscle.elements.size()
        << " elements (need one per element or a single shared one)";
      throw InvalidInputError(s.str());
    }
    for (size_t t = 0; t < muscle.fibers.size(); ++t) CheckDirection(Indexed(name + ".fibers", t), muscle.fibers[t]);
    CheckPositive(name + ".stiffness", muscle.stiffness, "Pa");
  }
}

void ValidateSurface(const std::string& name, const ContactSurface& surface) {
  switch (surface.kind) {
    case ContactSurface::Kind::kPlane:
      CheckDirection(name + ".normal", surface.normal);
      CheckFiniteScalar(name + ".offset", surface.offset, " (m)");
      break;
    case ContactSurface::Kind::kSphere:
      if (!surface.center.allFinite()) Invalid(name + ".center", Format(surface.center), "finite (m)");
      CheckPositive(name + ".radius", surface.radius, "m");
      break;
    case ContactSurface::Kind::kHeightField:
      if (!surface.height || !surface.height_gradient)
        throw InvalidInputError("scene: " + name + ": a height field needs both height and height_gradient");
      break;
    default:
      Invalid(name + ".kind", std::to_string(static_cast<int>(surface.kind)),
              "kPlane (0), kSphere (1) or kHeightField (2)");
  }
}

void ValidateContacts(const Scene& scene) {
  const int n = scene.mesh.num_vertices();
  std::vector<int> owner(n, -1);
  std::vector<char> has_dirichlet(n, 0);
  for (const int d : scene.dirichlet.dofs) has_dirichlet[d / 3] = 1;
  for (size_t c = 0; c < scene.frictional_contacts.size(); ++c) {
    const FrictionalContact& contact = scene.frictional_contacts[c];
    const std::string name = Indexed("frictional_contacts", c);
    ValidateSurface(name + ".surface", contact.surface);
    for (size_t k = 0; k < contact.nodes.size(); ++k) {
      const int i = contact.nodes[k];
      CheckNode(Indexed(name + ".nodes", k), i, n);
      if (owner[i] >= 0) {
        std::ostringstream s;
        s << "scene: node " << i << " is a candidate of frictional_contacts[" << owner[i] << "] and " << name
          << " (a node may be a frictional contact candidate once)";
        throw InvalidInputError(s.str());
      }
      owner[i] = static_cast<int>(c);
      if (has_dirichlet[i]) {
        std::ostringstream s;
        s << "scene: " << Indexed(name + ".nodes", k) << " = " << i
          << " has a Dirichlet DoF; frictional contact candidates must be free";
        throw InvalidInputError(s.str());
      }
    }
  }
  const FrictionalContactOptions& opt = scene.frictional_contact_options;
  if (opt.pd_linear_solve != ContactLinearSolve::kWoodbury && opt.pd_linear_solve != ContactLinearSolve::kRefactorize)
    Invalid("frictional_contact_options.pd_linear_solve", std::to_string(static_cast<int>(opt.pd_linear_solve)),
            "kWoodbury (0) or kRefactorize (1)");
  if (opt.max_passes < 1) Invalid("frictional_contact_options.max_passes", std::to_string(opt.max_passes), ">= 1");
  CheckNonNegative("frictional_contact_options.penetration_tolerance", opt.penetration_tolerance, " (m)");
  if (!(std::isfinite(opt.screening_rel_tolerance) && opt.screening_rel_tolerance >= 0 &&
        opt.screening_rel_tolerance < 1))
    Invalid("frictional_contact_options.screening_rel_tolerance", Str(opt.screening_rel_tolerance),
            "finite and in [0, 1)");
  if (!(opt.max_energy_gain >= 0))
    Invalid("frictional_contact_options.max_energy_gain", Str(opt.max_energy_gain), ">= 0 (infinity: no check)");
  for (size_t c = 0; c < scene.penalty_contacts.size(); ++c) {
    const PenaltyContact& contact = scene.penalty_contacts[c];
    const std::string name = Indexed("penalty_contacts", c);
    CheckDirection(name + ".normal", contact.normal);
    CheckFiniteScalar(name + ".offset", contact.offset, " (m)");
    for (size_t k = 0; k < contact.nodes.size(); ++k) CheckNode(Indexed(name + ".nodes", k), contact.nodes[k], n);
    CheckPositive(name + ".stiffness", contact.stiffness, "N/m");
    CheckNonNegative(name + ".friction", contact.friction, "");
    CheckPositive(name + ".friction_velocity", contact.friction_velocity, "m/s");
  }
}

void ValidateStateForces(const Scene& scene) {
  const int n = scene.mesh.num_vertices();
  if (scene.hydrodynamics) {
    const Hydrodynamics& hydro = *scene.hydrodynamics;
    for (int t = 0; t < hydro.triangles.cols(); ++t)
      for (int c = 0; c < 3; ++c) {
        const int i = hydro.triangles(c, t);
        if (i < 0 || i >= n) {
          std::ostringstream s;
          s << "scene: hydrodynamics.triangles(" << c << ", " << t << ") = " << i << " is out of range [0, " << n
            << ") (no such node)";
          throw InvalidInputError(s.str());
        }
      }
    CheckNonNegative("hydrodynamics.fluid_density", hydro.fluid_density, " (kg/m^3)");
    CheckNonNegative("hydrodynamics.drag_tangential", hydro.drag_tangential, "");
    CheckNonNegative("hydrodynamics.drag_normal", hydro.drag_normal, "");
    CheckFiniteScalar("hydrodynamics.thrust", hydro.thrust, "");
    if (!hydro.flow_velocity.allFinite())
      Invalid("hydrodynamics.flow_velocity", Format(hydro.flow_velocity), "finite (m/s)");
  }
  if (scene.quad_hydrodynamics) {
    const QuadHydrodynamics& quad = *scene.quad_hydrodynamics;
    for (int f = 0; f < quad.quads.cols(); ++f)
      for (int c = 0; c < 4; ++c) {
        const int i = quad.quads(c, f);
        if (i < 0 || i >= n) {
          std::ostringstream s;
          s << "scene: quad_hydrodynamics.quads(" << c << ", " << f << ") = " << i << " is out of range [0, " << n
            << ") (no such node)";
          throw InvalidInputError(s.str());
        }
      }
    CheckNonNegative("quad_hydrodynamics.fluid_density", quad.fluid_density, " (kg/m^3)");
    if (!quad.flow_velocity.allFinite())
      Invalid("quad_hydrodynamics.flow_velocity", Format(quad.flow_velocity), "finite (m/s)");
    for (const auto& [name, curve] : {std::pair{"quad_hydrodynamics.drag_curve", quad.drag_curve},
                                      {"quad_hydrodynamics.thrust_curve", quad.thrust_curve}})
      if (!curve.allFinite()) {
        std::ostringstream s;
        s << "(" << curve(0) << ", " << curve(1) << ", " << curve(2) << ", " << curve(3) << ")";
        Invalid(name, s.str(), "finite");
      }
  }
  if (scene.linear_damping) CheckNonNegative("linear_damping", *scene.linear_damping, " (1/s)");
}

}  // namespace

void ValidateOptionalTerms(const Scene& scene) {
  ValidateMuscles(scene);
  ValidateContacts(scene);
  ValidateStateForces(scene);
}

}  // namespace diffpd::internal
