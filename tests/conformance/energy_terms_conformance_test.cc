// Every energy, projection and state force of the library passes the
// conformance check of tests/util/energy_conformance.h, one table row per
// term: zero energy (force) at rest, frame indifference, gradient and Hessian
// (force differential, projection differential) against central differences
// at seeded random states, and idempotent projections that land in their set.
//
// Rows: the elastic densities (reference and solver kernels), the PD
// projections (rotation, unit determinant, muscle sphere) and the contact
// surfaces' projections, the body energies (elastic per energy set and
// element type, including the fused PD hexahedron kernel; muscles; penalty
// contact; the auxiliary energies together), the muscle force with its
// activation derivative, the drag and thrust on one triangle and on one
// one-sided quad, and the state forces (damping, hydrodynamics on triangles
// and on quads, penalty friction, all together) with their mass and parameter
// derivatives. A new term adds a row.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <functional>
#include <iostream>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "diffpd/contact.h"
#include "diffpd/material.h"
#include "diffpd/scene.h"
#include "diffpd/state_forces.h"
#include "fem/auxiliary_energies.h"
#include "fem/elastic_forces.h"
#include "fem/fem_model.h"
#include "fem/muscle_forces.h"
#include "fem/penalty_contact_energy.h"
#include "forces/hydrodynamic_force.h"
#include "forces/quad_hydrodynamic_force.h"
#include "forces/state_forces.h"
#include "material/density_kernels.h"
#include "material/projections.h"
#include "material/svd3.h"
#include "test_scenes.h"
#include "util/deformation.h"
#include "util/energy_conformance.h"

namespace diffpd {
namespace {

using testing::ConformanceResult;
using testing::EnergyTerm;
using testing::ForceTerm;
using testing::ProjectionTerm;
using testing::Symmetry;

constexpr double kMu = 1.3, kLambda = 2.1;

// ---- symmetries --------------------------------------------------------

// F -> Q F (frame rotation) and F -> F Q (material rotation: isotropy), on vec(F).
Symmetry LeftRotation() {
  return {"frame rotation",
          [](const VectorXd& f, const Mat3& q) -> VectorXd { return testing::Flatten(q * testing::Unflatten(f)); },
          {},
          {}};
}
Symmetry RightRotation() {
  return {"material rotation",
          [](const VectorXd& f, const Mat3& q) -> VectorXd { return testing::Flatten(testing::Unflatten(f) * q); },
          {},
          {}};
}
// Every node (velocity, force) rotated about the origin.
Symmetry NodeRotation() { return {"frame rotation", testing::RotateEach3, {}, {}}; }
// Rotations about the axis n through the origin (they keep n . x).
Symmetry NodeRotationAbout(const Vec3& n) {
  return {"rotation about the wall normal", testing::RotateEach3, {}, [n](std::mt19937_64* rng) {
            return testing::RandomRotationAbout(n, rng);
          }};
}

// ---- deformation gradients ---------------------------------------------

// Near rest (I plus entries in +-0.3) and large (singular values in [0.2, 5]),
// alternately; inverted (one singular value negated) every third large one
// when `inverted`.
std::function<VectorXd(std::mt19937_64*)> RandomDeformation(bool inverted) {
  auto count = std::make_shared<int>(0);
  return [count, inverted](std::mt19937_64* rng) -> VectorXd {
    std::uniform_real_distribution<double> small(-0.3, 0.3), large(0.2, 5.0);
    const int n = (*count)++;
    Mat3 F = Mat3::Identity();
    if (n % 2 == 0) {
      for (int i = 0; i < 9; ++i) F(i) += small(*rng);
    } else {
      Vec3 sigma(large(*rng), large(*rng), large(*rng));
      if (inverted && n % 3 == 1) sigma(2) = -sigma(2);
      F = testing::RandomRotation(rng) * sigma.asDiagonal() * testing::RandomRotation(rng);
    }
    return testing::Flatten(F);
  };
}

testing::TermScales DensityScales() {
  testing::TermScales s;
  // Rounding is relative to the terms, mu |F|^2 and lambda J^2, not to the
  // (small near rest) energy.
  s.value = [](const VectorXd& f) {
    const Mat3 F = testing::Unflatten(f);
    return (kMu + kLambda) * std::max({1.0, F.squaredNorm(), F.determinant() * F.determinant()});
  };
  s.input = [](const VectorXd& f) { return testing::DeformationScale(testing::Unflatten(f)); };
  return s;
}

// The reference density of material.h.
EnergyTerm ReferenceDensity(ElasticEnergy e) {
  EnergyTerm t;
  t.name = std::string("density ") + ToString(e);
  t.energy = [e](const VectorXd& f) { return EnergyDensity(e, testing::Unflatten(f), kMu, kLambda); };
  t.gradient = [e](const VectorXd& f) -> VectorXd {
    return testing::Flatten(FirstPiolaStress(e, testing::Unflatten(f), kMu, kLambda));
  };
  t.hessian_product = [e](const VectorXd& f, const VectorXd& z) -> VectorXd {
    return StressDifferential(e, testing::Unflatten(f), kMu, kLambda) * z;
  };
  t.random_state = RandomDeformation(e != ElasticEnergy::kNeoHookean);
  t.rest = testing::Flatten(Mat3::Identity());
  if (e != ElasticEnergy::kLinear) t.symmetries = {LeftRotation(), RightRotation()};
  t.scales = DensityScales();
  return t;
}

// The solver kernels of density_kernels.h: energy and stress from one SVD,
// the differential assembled from its singular-value coefficients.
EnergyTerm KernelDensity(ElasticEnergy e) {
  EnergyTerm t = ReferenceDensity(e);
  t.name = std::string("kernel ") + ToString(e);
  t.energy = [e](const VectorXd& f) {
    const Mat3 F = testing::Unflatten(f);
    return internal::EnergyAndStress(e, F, internal::ComputeSvd3(F), kMu, kLambda, nullptr);
  };
  t.gradient = [e](const VectorXd& f) -> VectorXd {
    const Mat3 F = testing::Unflatten(f);
    Mat3 stress;
    internal::EnergyAndStress(e, F, internal::ComputeSvd3(F), kMu, kLambda, &stress);
    return testing::Flatten(stress);
  };
  t.hessian_product = [e](const VectorXd& f, const VectorXd& z) -> VectorXd {
    const Mat3 F = testing::Unflatten(f);
    return internal::StressDifferential(e, F, internal::ComputeSvd3(F), kMu, kLambda) * z;
  };
  return t;
}

// The densities of several energies summed with one shared SVD
// (EvaluateDensity, the element loop's evaluation).
EnergyTerm SummedDensity(const std::vector<ElasticEnergy>& energies, const std::string& name) {
  EnergyTerm t = ReferenceDensity(energies[0]);
  t.name = name;
  const auto evaluate = [energies](const VectorXd& f, Mat3* stress, Mat9* dstress) {
    return internal::EvaluateDensity(energies, testing::Unflatten(f), kMu, kLambda, stress, dstress);
  };
  t.energy = [evaluate](const VectorXd& f) { return evaluate(f, nullptr, nullptr); };
  t.gradient = [evaluate](const VectorXd& f) -> VectorXd {
    Mat3 stress;
    evaluate(f, &stress, nullptr);
    return testing::Flatten(stress);
  };
  t.hessian_product = [evaluate](const VectorXd& f, const VectorXd& z) -> VectorXd {
    Mat3 stress;
    Mat9 dstress;
    evaluate(f, &stress, &dstress);
    return dstress * z;
  };
  return t;
}

// ---- projections -------------------------------------------------------

// Proj(F) of a projective energy, the PD extension point (density_kernels.h).
ProjectionTerm PdProjection(ElasticEnergy e) {
  ProjectionTerm t;
  t.name = std::string("PD projection of ") + ToString(e);
  t.project = [e](const VectorXd& f) -> VectorXd {
    return testing::Flatten(internal::Projection(e, internal::ComputeSvd3(testing::Unflatten(f))));
  };
  t.differential = [e](const VectorXd& f, const VectorXd& z) -> VectorXd {
    return internal::ProjectionDifferential(e, internal::ComputeSvd3(testing::Unflatten(f))) * z;
  };
  t.random_state = RandomDeformation(true);
  if (e == ElasticEnergy::kPdCorotated) {
    t.violation = [](const VectorXd& p) {
      const Mat3 R = testing::Unflatten(p);
      return (R.transpose() * R - Mat3::Identity()).norm() + std::abs(R.determinant() - 1);
    };
  } else {
    t.violation = [](const VectorXd& p) { return testing::Unflatten(p).determinant() - 1; };
  }
  t.symmetries = {LeftRotation(), RightRotation()};
  t.scales.input = DensityScales().input;
  return t;
}

// The muscle fibre's projection onto the sphere |p| = a.
ProjectionTerm SphereProjection() {
  const double radius = 0.9;
  ProjectionTerm t;
  t.name = "PD projection of a muscle fibre (sphere)";
  t.project = [radius](const VectorXd& f) -> VectorXd { return internal::ProjectToSphere(f, radius); };
  t.differential = [radius](const VectorXd& f, const VectorXd& z) -> VectorXd {
    return internal::SphereProjectionDifferential(f, radius) * z;
  };
  t.random_state = [](std::mt19937_64* rng) -> VectorXd {
    std::normal_distribution<double> normal;
    return Vec3(normal(*rng), normal(*rng), normal(*rng));
  };
  t.violation = [radius](const VectorXd& p) { return p.norm() - radius; };
  t.symmetries = {NodeRotation()};
  return t;
}

// A frictional contact surface's projection (the pins' positions).
ProjectionTerm SurfaceProjection(const std::string& name, const ContactSurface& surface, std::vector<Symmetry> sym) {
  ProjectionTerm t;
  t.name = "contact surface projection, " + name;
  t.project = [surface](const VectorXd& x) -> VectorXd { return surface.Project(x); };
  t.differential = [surface](const VectorXd& x, const VectorXd& z) -> VectorXd {
    return surface.ProjectJacobian(x) * z;
  };
  t.random_state = [](std::mt19937_64* rng) -> VectorXd {
    std::uniform_real_distribution<double> u(-0.1, 0.1);
    return Vec3(u(*rng), u(*rng), 0.02 + u(*rng));
  };
  t.violation = [surface](const VectorXd& p) { return surface.Gap(p); };
  t.symmetries = std::move(sym);
  t.scales.input = [](const VectorXd&) { return 0.1; };  // m, the surfaces' curvature scale
  return t;
}

// ---- bodies ------------------------------------------------------------

// A beam's rest positions moved by a smooth bend and twist plus per-node
// noise (random amplitudes), as in elastic_forces_test.
VectorXd BentBeam(const Mesh& mesh, std::mt19937_64* rng, double noise) {
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> amplitude(0.5, 1.5);
  const double twist = 3.0 * amplitude(*rng), bend = 0.5 * amplitude(*rng);
  VectorXd x(mesh.num_dofs());
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3 p = mesh.vertices.col(v);
    const double a = twist * p(0);
    x.segment<3>(3 * v) = Vec3(p(0) * 1.05, std::cos(a) * p(1) - std::sin(a) * p(2) + bend * p(0) * p(0),
                               std::sin(a) * p(1) + std::cos(a) * p(2));
    for (int d = 0; d < 3; ++d) x(3 * v + d) += noise * normal(*rng);
  }
  return x;
}

VectorXd RestPositions(const Mesh& mesh) { return Eigen::Map<const VectorXd>(mesh.vertices.data(), mesh.num_dofs()); }

// Node-position terms: the step's scale is half the element size (the
// beams' elements are 4 and 5 cm); rounding relative to the energy itself.
testing::TermScales BodyScales() {
  testing::TermScales s;
  s.input = [](const VectorXd&) { return 0.02; };
  return s;
}

// The elastic energy of a beam (ElasticForces): energy, gradient, and the
// packed element Hessians' product (what Newton assembles).
EnergyTerm ElasticBody(bool tets, const std::vector<ElasticEnergy>& energies, const std::string& name) {
  struct Body {
    Scene scene;
    internal::FemModel fem;
    internal::ElasticForces forces;
    Body(bool tets, const std::vector<ElasticEnergy>& energies)
        : scene(testing::SmallBeamScene(tets, energies)), fem(scene.mesh), forces(fem, energies) {}
  };
  auto body = std::make_shared<Body>(tets, energies);
  const double mu = 7e4, lambda = 2.8e5;
  const internal::LameField lame = internal::LameField::Uniform(mu, lambda);
  EnergyTerm t;
  t.name = "elastic body, " + name + (tets ? ", tetrahedra" : ", hexahedra");
  t.energy = [body, lame](const VectorXd& x) { return body->forces.EnergyAndGradient(x, lame, nullptr, 1); };
  t.gradient = [body, lame](const VectorXd& x) {
    VectorXd g;
    body->forces.EnergyAndGradient(x, lame, &g, 1);
    return g;
  };
  t.hessian_product = [body, lame](const VectorXd& x, const VectorXd& z) {
    std::vector<double> packed;
    body->forces.PackedElementHessians(x, lame, &packed, 1);
    VectorXd out;
    body->forces.ApplyElementMatrices(packed, z, &out, 1);
    return out;
  };
  t.random_state = [body](std::mt19937_64* rng) { return BentBeam(body->scene.mesh, rng, 2e-3); };
  t.rest = RestPositions(body->scene.mesh);
  const bool linear = std::find(energies.begin(), energies.end(), ElasticEnergy::kLinear) != energies.end();
  if (!linear) t.symmetries = {NodeRotation()};
  t.scales = BodyScales();
  return t;
}

// Two muscles on a 2-element box (the second element in both), as in
// muscle_forces_test.
struct MuscleBody {
  Mesh mesh;
  internal::FemModel fem;
  std::vector<Muscle> muscles;
  internal::MuscleForces forces;
  explicit MuscleBody(bool tets)
      : mesh(tets ? testing::BoxTetMesh(2, 1, 1, 0.1, 0.05, 0.05) : testing::BoxHexMesh(2, 1, 1, 0.1, 0.05, 0.05)),
        fem(mesh),
        muscles(MakeMuscles()),
        forces(fem, muscles) {}
  static std::vector<Muscle> MakeMuscles() {
    Muscle a, b;
    a.elements = {0, 1};
    a.fibers = {Vec3(1, 0, 0), Vec3(1, 1, 0)};
    a.stiffness = 2e5;
    b.elements = {1};
    b.fibers = {Vec3(0, 0, 3)};
    b.stiffness = 5e4;
    return {a, b};
  }
  VectorXd Random(std::mt19937_64* rng) const {
    std::normal_distribution<double> normal(0.0, 0.005);
    VectorXd x = RestPositions(mesh);
    for (int i = 0; i < x.size(); ++i) x(i) += normal(*rng);
    return x;
  }
};

// The muscle energy at fixed activations (empty: rest, a = 1).
EnergyTerm MuscleEnergy(bool tets, const VectorXd& activation) {
  auto body = std::make_shared<MuscleBody>(tets);
  EnergyTerm t;
  t.name = std::string("muscle energy, ") + (activation.size() ? "contracted and extended" : "rest activation") +
           (tets ? ", tetrahedra" : ", hexahedra");
  t.energy = [body, activation](const VectorXd& x) {
    return body->forces.AddEnergyAndGradient(x, activation, nullptr);
  };
  t.gradient = [body, activation](const VectorXd& x) {
    VectorXd g = VectorXd::Zero(x.size());
    body->forces.AddEnergyAndGradient(x, activation, &g);
    return g;
  };
  t.hessian_product = [body, activation](const VectorXd& x, const VectorXd& z) {
    VectorXd out = VectorXd::Zero(x.size());
    body->forces.AddHessianProduct(x, activation, z, &out);
    return out;
  };
  t.random_state = [body](std::mt19937_64* rng) { return body->Random(rng); };
  if (activation.size() == 0) t.rest = RestPositions(body->mesh);
  t.symmetries = {NodeRotation()};
  t.scales = BodyScales();
  return t;
}

// The muscle force -dE/dx on y = (x, activations): its differential in x is
// -H, in the activations ActivationGradient (z . d(-dE/dx)/da).
ForceTerm MuscleForce(bool tets) {
  auto body = std::make_shared<MuscleBody>(tets);
  const int n = body->mesh.num_dofs(), m = 2;
  ForceTerm t;
  t.name = std::string("muscle force with activations") + (tets ? ", tetrahedra" : ", hexahedra");
  t.force = [body, n, m](const VectorXd& y) {
    VectorXd g = VectorXd::Zero(n);
    body->forces.AddEnergyAndGradient(y.head(n), y.tail(m), &g);
    return VectorXd(-g);
  };
  t.vjp = [body, n, m](const VectorXd& y, const VectorXd& w) {
    VectorXd out(n + m), hw = VectorXd::Zero(n);
    body->forces.AddHessianProduct(y.head(n), y.tail(m), w, &hw);
    out.head(n) = -hw;
    out.tail(m) = body->forces.ActivationGradient(y.head(n), y.tail(m), w);
    return out;
  };
  t.random_state = [body, n, m](std::mt19937_64* rng) {
    std::uniform_real_distribution<double> a(0.7, 1.3);
    VectorXd y(n + m);
    y.head(n) = body->Random(rng);
    y.tail(m) = Eigen::Vector2d(a(*rng), a(*rng));
    return y;
  };
  VectorXd rest(n + m);
  rest << RestPositions(body->mesh), Eigen::Vector2d::Ones();
  t.rest = rest;
  t.symmetries = {{"frame rotation",
                   [n](const VectorXd& y, const Mat3& q) {
                     VectorXd out = y;
                     out.head(n) = testing::RotateEach3(y.head(n), q);
                     return out;
                   },
                   testing::RotateEach3,
                   {}}};
  t.scales.input = [](const VectorXd&) { return 0.02; };
  return t;
}

// A wall n . x >= offset the box's lower nodes reach into.
PenaltyContact Wall() {
  PenaltyContact wall;
  wall.normal = Vec3(0.3, 0, 1);
  wall.offset = 0.005;
  wall.stiffness = 500;
  return wall;
}

EnergyTerm PenaltyEnergy() {
  struct Body {
    Mesh mesh = testing::BoxHexMesh(2, 1, 1, 0.1, 0.05, 0.05);
    internal::FemModel fem{mesh};
    PenaltyContact wall = Wall();
    std::unique_ptr<internal::PenaltyContactEnergy> energy;
  };
  auto body = std::make_shared<Body>();
  for (int i = 0; i < body->mesh.num_vertices(); ++i) body->wall.nodes.push_back(i);
  body->energy = std::make_unique<internal::PenaltyContactEnergy>(body->fem, std::vector<PenaltyContact>{body->wall});
  EnergyTerm t;
  t.name = "penalty contact energy";
  t.energy = [body](const VectorXd& x) { return body->energy->AddEnergyAndGradient(x, nullptr); };
  t.gradient = [body](const VectorXd& x) {
    VectorXd g = VectorXd::Zero(x.size());
    body->energy->AddEnergyAndGradient(x, &g);
    return g;
  };
  t.hessian_product = [body](const VectorXd& x, const VectorXd& z) {
    VectorXd out = VectorXd::Zero(x.size());
    body->energy->AddHessianProduct(x, z, &out);
    return out;
  };
  t.random_state = [body](std::mt19937_64* rng) {
    std::normal_distribution<double> normal(0.0, 0.003);
    VectorXd x = RestPositions(body->mesh);
    for (int i = 0; i < x.size(); ++i) x(i) += normal(*rng) - (i % 3 == 2 ? 0.004 : 0.0);  // pushed into the wall
    return x;
  };
  // Lifted clear of the wall.
  VectorXd lifted = RestPositions(body->mesh);
  for (int i = 0; i < body->mesh.num_vertices(); ++i) lifted(3 * i + 2) += 0.01;
  t.rest = lifted;
  t.symmetries = {NodeRotationAbout(body->wall.normal.normalized())};
  t.scales = BodyScales();
  return t;
}

// Muscles and penalty contact as the solvers see them (AuxiliaryEnergies).
EnergyTerm AuxiliaryBody() {
  struct Body {
    Scene scene;
    internal::FemModel fem;
    internal::AuxiliaryEnergies energies;
    explicit Body(Scene s) : scene(std::move(s)), fem(scene.mesh), energies(fem, scene) {}
  };
  Scene scene;
  scene.mesh = testing::BoxHexMesh(2, 1, 1, 0.1, 0.05, 0.05);
  scene.muscles = MuscleBody::MakeMuscles();
  PenaltyContact wall = Wall();
  wall.normal = Vec3(0, 0, 1);
  for (int i = 0; i < scene.mesh.num_vertices(); ++i) wall.nodes.push_back(i);
  scene.penalty_contacts = {wall};
  auto body = std::make_shared<Body>(scene);
  const VectorXd activation = Eigen::Vector2d(0.9, 1.1);
  EnergyTerm t;
  t.name = "auxiliary energies (muscles and penalty contact)";
  t.energy = [body, activation](const VectorXd& x) {
    return body->energies.AddEnergyAndGradient(x, activation, nullptr);
  };
  t.gradient = [body, activation](const VectorXd& x) {
    VectorXd g = VectorXd::Zero(x.size());
    body->energies.AddEnergyAndGradient(x, activation, &g);
    return g;
  };
  t.hessian_product = [body, activation](const VectorXd& x, const VectorXd& z) {
    VectorXd out = VectorXd::Zero(x.size());
    body->energies.AddHessianProduct(x, activation, z, &out);
    return out;
  };
  t.random_state = [body](std::mt19937_64* rng) {
    std::normal_distribution<double> normal(0.0, 0.003);
    VectorXd x = RestPositions(body->scene.mesh);
    for (int i = 0; i < x.size(); ++i) x(i) += normal(*rng);
    return x;
  };
  // Rotations about the wall's normal keep both terms.
  t.symmetries = {NodeRotationAbout(Vec3::UnitZ())};
  t.scales = BodyScales();
  return t;
}

// ---- forces ------------------------------------------------------------

// Drag and thrust on one triangle, y = (area vector N, relative velocity u,
// fluid_density, drag_tangential, drag_normal, thrust).
ForceTerm TriangleDrag() {
  const auto params = [](const VectorXd& y) {
    Hydrodynamics p;
    p.fluid_density = y(6);
    p.drag_tangential = y(7);
    p.drag_normal = y(8);
    p.thrust = y(9);
    return p;
  };
  ForceTerm t;
  t.name = "drag and thrust on a triangle";
  t.force = [params](const VectorXd& y) -> VectorXd {
    return internal::HydrodynamicForce(params(y), y.segment<3>(0), y.segment<3>(3));
  };
  t.vjp = [params](const VectorXd& y, const VectorXd& w) {
    Vec3 g_area, g_u;
    StateForceGradient grad;
    internal::HydrodynamicForceVjp(params(y), y.segment<3>(0), y.segment<3>(3), w, &g_area, &g_u, &grad);
    VectorXd out(10);
    out << g_area, g_u, grad.fluid_density, grad.drag_tangential, grad.drag_normal, grad.thrust;
    return out;
  };
  t.random_state = [](std::mt19937_64* rng) {
    std::normal_distribution<double> normal;
    std::uniform_real_distribution<double> coefficient(0.05, 2.0);
    VectorXd y(10);
    y << 0.01 * normal(*rng), 0.01 * normal(*rng), 0.01 * normal(*rng), normal(*rng), normal(*rng), normal(*rng),
        1000 * coefficient(*rng), coefficient(*rng), coefficient(*rng), coefficient(*rng) - 1;
    return y;
  };
  VectorXd rest(10);
  rest << 0.01, 0.005, 0.002, 0, 0, 0, 1000, 0.05, 2.05, 0.6;  // u = 0
  t.rest = rest;
  t.symmetries = {{"frame rotation",
                   [](const VectorXd& y, const Mat3& q) {
                     VectorXd out = y;
                     out.segment<3>(0) = q * y.segment<3>(0);
                     out.segment<3>(3) = q * y.segment<3>(3);
                     return out;
                   },
                   [](const VectorXd& f, const Mat3& q) -> VectorXd { return q * f; },
                   {}}};
  // Each block changes over its own magnitude; the smallest, |N| ~ 0.01 m^2, sets the step.
  t.scales.input = [](const VectorXd& y) { return y.segment<3>(0).norm(); };
  return t;
}

// The state forces of a scene on y = (x, v, lumped mass M (3n), linear_damping,
// fluid_density, drag_tangential, drag_normal, thrust, flow_velocity (3),
// friction of penalty_contacts[0]) with the vector-Jacobian products of
// StateForces::AddVjp (the parameters a scene does not declare have none).
ForceTerm StateForceTerm(const std::string& name, const Scene& scene, std::vector<Symmetry> symmetries) {
  const int n = scene.mesh.num_dofs(), p = 9;
  const auto scene_of = [scene, n](const VectorXd& y) {
    Scene s = scene;
    const VectorXd q = y.tail(9);
    if (s.linear_damping) s.linear_damping = q(0);
    if (s.hydrodynamics) {
      s.hydrodynamics->fluid_density = q(1);
      s.hydrodynamics->drag_tangential = q(2);
      s.hydrodynamics->drag_normal = q(3);
      s.hydrodynamics->thrust = q(4);
      s.hydrodynamics->flow_velocity = q.segment<3>(5);
    }
    if (!s.penalty_contacts.empty()) s.penalty_contacts[0].friction = q(8);
    return s;
  };
  ForceTerm t;
  t.name = "state forces, " + name;
  t.force = [scene_of, n](const VectorXd& y) {
    VectorXd f = VectorXd::Zero(n);
    internal::StateForces(scene_of(y)).Add(y.segment(0, n), y.segment(n, n), y.segment(2 * n, n), {}, &f);
    return f;
  };
  t.vjp = [scene_of, n, p](const VectorXd& y, const VectorXd& w) {
    VectorXd gx = VectorXd::Zero(n), gv = VectorXd::Zero(n), dmass = VectorXd::Zero(n);
    StateForceGradient grad;
    internal::StateForces(scene_of(y))
        .AddVjp(y.segment(0, n), y.segment(n, n), y.segment(2 * n, n), {}, w, &gx, &gv, &grad, &dmass);
    VectorXd out(3 * n + p);
    out << gx, gv, dmass, grad.linear_damping, grad.fluid_density, grad.drag_tangential, grad.drag_normal, grad.thrust,
        grad.flow_velocity, grad.penalty_friction.empty() ? 0.0 : grad.penalty_friction[0];
    return out;
  };
  auto fem = std::make_shared<internal::FemModel>(scene.mesh);
  auto mesh = std::make_shared<Mesh>(scene.mesh);
  const auto parameters = [scene](const Vec3& flow) {
    VectorXd q(9);
    const Hydrodynamics h = scene.hydrodynamics.value_or(Hydrodynamics());
    q << scene.linear_damping.value_or(0.0), h.fluid_density, h.drag_tangential, h.drag_normal, h.thrust, flow,
        scene.penalty_contacts.empty() ? 0.0 : scene.penalty_contacts[0].friction;
    return q;
  };
  const auto state = [fem, n, parameters](const VectorXd& x, const VectorXd& v, const Vec3& flow) {
    VectorXd y(3 * n + 9), mass(n);
    for (int i = 0; i < n / 3; ++i) mass.segment<3>(3 * i).setConstant(800 * fem->unit_lumped_mass()(i));
    y << x, v, mass, parameters(flow);
    return y;
  };
  const Vec3 flow = scene.hydrodynamics ? scene.hydrodynamics->flow_velocity : Vec3::Zero();
  t.random_state = [mesh, state, n, flow](std::mt19937_64* rng) {
    std::normal_distribution<double> position(0.0, 0.003), velocity(0.0, 0.2);
    VectorXd x = RestPositions(*mesh), v(n);
    for (int i = 0; i < n; ++i) {
      x(i) += position(*rng);
      v(i) = velocity(*rng);
    }
    return state(x, v, flow);
  };
  t.rest = state(RestPositions(*mesh), VectorXd::Zero(n), Vec3::Zero());  // at rest in still water
  const auto rotate_state = [n](const VectorXd& y, const Mat3& q) {
    VectorXd out = y;
    out.segment(0, n) = testing::RotateEach3(y.segment(0, n), q);
    out.segment(n, n) = testing::RotateEach3(y.segment(n, n), q);
    out.segment<3>(3 * n + 5) = q * y.segment<3>(3 * n + 5);  // the flow
    return out;
  };
  for (Symmetry& s : symmetries) {
    s.act = rotate_state;
    s.act_on_value = testing::RotateEach3;
  }
  t.symmetries = std::move(symmetries);
  t.scales.input = [](const VectorXd&) { return 0.02; };  // the smallest block scale: positions (element size)
  return t;
}

Scene SwimmerBox() {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(2, 2, 1, 0.1, 0.1, 0.05);
  return scene;
}

Scene Damped() {
  Scene s = SwimmerBox();
  s.linear_damping = 0.5;
  return s;
}
Scene Swimming() {
  Scene s = SwimmerBox();
  Hydrodynamics hydro;
  hydro.triangles = BoundaryTriangles(s.mesh);
  hydro.thrust = 0.6;
  hydro.flow_velocity = Vec3(0.1, -0.05, 0.02);
  s.hydrodynamics = hydro;
  return s;
}
Scene Sliding() {
  Scene s = SwimmerBox();
  PenaltyContact floor;
  floor.offset = 0.002;  // the bottom nodes start 2 mm inside
  floor.stiffness = 200;
  floor.friction = 0.4;
  floor.friction_velocity = 0.05;
  for (int i = 0; i < s.mesh.num_vertices(); ++i)
    if (s.mesh.vertices(2, i) < 1e-9) floor.nodes.push_back(i);
  s.penalty_contacts = {floor};
  return s;
}
Scene AllStateForces() {
  Scene s = Swimming();
  s.linear_damping = 0.5;
  s.penalty_contacts = Sliding().penalty_contacts;
  return s;
}

Symmetry AnyRotation() { return {"frame rotation", {}, {}, {}}; }
Symmetry RotationAboutZ() {
  return {"rotation about the floor normal", {}, {}, [](std::mt19937_64* rng) {
            return testing::RandomRotationAbout(Vec3::UnitZ(), rng);
          }};
}

// Drag and thrust on one one-sided quad, y = (corners p_0..p_3 (12), relative
// velocity u (3), fluid_density, drag_curve (4), thrust_curve (4)). The
// states have the face moving into the water (n . u < 0, away from the
// switch at n . u = 0, where the force jumps).
ForceTerm QuadDrag() {
  const auto params = [](const VectorXd& y) {
    QuadHydrodynamics p;
    p.fluid_density = y(15);
    p.drag_curve = y.segment<4>(16);
    p.thrust_curve = y.segment<4>(20);
    return p;
  };
  const auto corners = [](const VectorXd& y) {
    return std::array<Vec3, 4>{y.segment<3>(0), y.segment<3>(3), y.segment<3>(6), y.segment<3>(9)};
  };
  ForceTerm t;
  t.name = "drag and thrust on a one-sided quad";
  t.force = [params, corners](const VectorXd& y) -> VectorXd {
    return internal::QuadHydrodynamicForce(params(y), corners(y), y.segment<3>(12));
  };
  t.vjp = [params, corners](const VectorXd& y, const VectorXd& w) {
    std::array<Vec3, 4> g_corners;
    Vec3 g_u;
    QuadHydrodynamicsGradient grad;
    internal::QuadHydrodynamicForceVjp(params(y), corners(y), y.segment<3>(12), w, &g_corners, &g_u, &grad);
    VectorXd out(24);
    out << g_corners[0], g_corners[1], g_corners[2], g_corners[3], g_u, grad.fluid_density, grad.drag_curve,
        grad.thrust_curve;
    return out;
  };
  t.random_state = [](std::mt19937_64* rng) {
    std::normal_distribution<double> normal;
    VectorXd y(24);
    // A warped 0.1 m square in the xy plane (normal +z).
    const double square[4][2] = {{0, 0}, {0.1, 0}, {0.1, 0.1}, {0, 0.1}};
    for (int c = 0; c < 4; ++c)
      y.segment<3>(3 * c) = Vec3(square[c][0], square[c][1], 0) + 0.01 * Vec3(normal(*rng), normal(*rng), normal(*rng));
    Vec3 u;
    do {
      u = Vec3(normal(*rng), normal(*rng), normal(*rng));
      if (u.z() > 0) u.z() = -u.z();
    } while (u.z() > -0.2 * u.norm());  // n . d < -0.2
    y.segment<3>(12) = u;
    y(15) = 1000 * (0.5 + std::abs(normal(*rng)));
    for (int i = 0; i < 8; ++i) y(16 + i) = normal(*rng);
    return y;
  };
  VectorXd rest = VectorXd::Zero(24);
  rest.segment<3>(3) = Vec3(0.1, 0, 0);
  rest.segment<3>(6) = Vec3(0.1, 0.1, 0);
  rest.segment<3>(9) = Vec3(0, 0.1, 0);
  rest(15) = 1000;
  rest.segment<4>(16) = QuadHydrodynamics().drag_curve;
  rest.segment<4>(20) = QuadHydrodynamics().thrust_curve;  // u = 0: no force
  t.rest = rest;
  t.symmetries = {{"frame rotation",
                   [](const VectorXd& y, const Mat3& q) {
                     VectorXd out = y;
                     for (int b = 0; b < 5; ++b) out.segment<3>(3 * b) = q * y.segment<3>(3 * b);
                     return out;
                   },
                   [](const VectorXd& f, const Mat3& q) -> VectorXd { return q * f; },
                   {}}};
  // The corners' warp (0.01 m) is the smallest scale the force changes over.
  t.scales.input = [](const VectorXd&) { return 0.01; };
  return t;
}

// The quad hydrodynamics of a scene as a state force on y = (x, v,
// fluid_density, flow_velocity (3), drag_curve (4), thrust_curve (4)):
// the corner shares of StateForces::Add and their products in AddVjp.
ForceTerm QuadStateForceTerm() {
  Scene scene = SwimmerBox();
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(scene.mesh);
  scene.quad_hydrodynamics = water;
  const int n = scene.mesh.num_dofs(), p = 12;
  const auto scene_of = [scene, n](const VectorXd& y) {
    Scene s = scene;
    s.quad_hydrodynamics->fluid_density = y(2 * n);
    s.quad_hydrodynamics->flow_velocity = y.segment<3>(2 * n + 1);
    s.quad_hydrodynamics->drag_curve = y.segment<4>(2 * n + 4);
    s.quad_hydrodynamics->thrust_curve = y.segment<4>(2 * n + 8);
    return s;
  };
  const VectorXd mass = VectorXd::Ones(n);  // quad hydrodynamics does not depend on the mass
  ForceTerm t;
  t.name = "state forces, drag and thrust on one-sided quads";
  t.force = [scene_of, n, mass](const VectorXd& y) {
    VectorXd f = VectorXd::Zero(n);
    internal::StateForces(scene_of(y)).Add(y.segment(0, n), y.segment(n, n), mass, {}, &f);
    return f;
  };
  t.vjp = [scene_of, n, p, mass](const VectorXd& y, const VectorXd& w) {
    VectorXd gx = VectorXd::Zero(n), gv = VectorXd::Zero(n), dmass = VectorXd::Zero(n);
    StateForceGradient grad;
    internal::StateForces(scene_of(y)).AddVjp(y.segment(0, n), y.segment(n, n), mass, {}, w, &gx, &gv, &grad, &dmass);
    EXPECT_EQ(dmass.norm(), 0.0);
    const QuadHydrodynamicsGradient& q = grad.quad_hydrodynamics;
    VectorXd out(2 * n + p);
    out << gx, gv, q.fluid_density, q.flow_velocity, q.drag_curve, q.thrust_curve;
    return out;
  };
  const auto mesh = std::make_shared<Mesh>(scene.mesh);
  const auto state = [n, water](const VectorXd& x, const VectorXd& v, const Vec3& flow) {
    VectorXd y(2 * n + 12);
    y << x, v, water.fluid_density, flow, water.drag_curve, water.thrust_curve;
    return y;
  };
  t.random_state = [mesh, state, n](std::mt19937_64* rng) {
    std::normal_distribution<double> position(0.0, 0.003), velocity(0.0, 0.2);
    VectorXd x = RestPositions(*mesh), v(n);
    for (int i = 0; i < n; ++i) {
      x(i) += position(*rng);
      v(i) = velocity(*rng);
    }
    return state(x, v, Vec3(0.1, -0.05, 0.02));
  };
  t.rest = state(RestPositions(*mesh), VectorXd::Zero(n), Vec3::Zero());  // at rest in still water
  t.symmetries = {{"frame rotation",
                   [n](const VectorXd& y, const Mat3& q) {
                     VectorXd out = y;
                     out.segment(0, n) = testing::RotateEach3(y.segment(0, n), q);
                     out.segment(n, n) = testing::RotateEach3(y.segment(n, n), q);
                     out.segment<3>(2 * n + 1) = q * y.segment<3>(2 * n + 1);
                     return out;
                   },
                   testing::RotateEach3,
                   {}}};
  t.scales.input = [](const VectorXd&) { return 0.02; };  // positions: the element size
  return t;
}

// ---- the table ---------------------------------------------------------

struct Row {
  std::string name;
  std::function<ConformanceResult()> check;
};

std::string Id(std::string name) {
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

template <class MakeTerm>
Row EnergyRow(const std::string& id, MakeTerm make) {
  return {id, [make] { return testing::CheckEnergyConformance(make()); }};
}
template <class MakeTerm>
Row ForceRow(const std::string& id, MakeTerm make) {
  return {id, [make] { return testing::CheckForceConformance(make()); }};
}
template <class MakeTerm>
Row ProjectionRow(const std::string& id, MakeTerm make) {
  return {id, [make] { return testing::CheckProjectionConformance(make()); }};
}

std::vector<Row> Rows() {
  using E = ElasticEnergy;
  std::vector<Row> rows;
  for (const E e : {E::kLinear, E::kCorotated, E::kNeoHookean, E::kPdCorotated, E::kPdVolume}) {
    rows.push_back(EnergyRow(std::string("density_") + ToString(e), [e] { return ReferenceDensity(e); }));
    rows.push_back(EnergyRow(std::string("kernel_") + ToString(e), [e] { return KernelDensity(e); }));
  }
  rows.push_back(EnergyRow("density_pd_pair_shared_svd", [] {
    return SummedDensity({E::kPdCorotated, E::kPdVolume}, "pd-corotated + pd-volume, one shared SVD");
  }));
  rows.push_back(EnergyRow("density_corotated_linear_shared_svd", [] {
    EnergyTerm t = SummedDensity({E::kCorotated, E::kLinear}, "corotated + linear, one shared SVD");
    t.symmetries.clear();  // the linear part is not rotation invariant
    return t;
  }));
  rows.push_back(ProjectionRow("projection_pd_corotated", [] { return PdProjection(E::kPdCorotated); }));
  rows.push_back(ProjectionRow("projection_pd_volume", [] { return PdProjection(E::kPdVolume); }));
  rows.push_back(ProjectionRow("projection_muscle_sphere", [] { return SphereProjection(); }));
  rows.push_back(ProjectionRow("projection_contact_plane", [] {
    const Vec3 n = Vec3(0.2, -0.1, 1.0).normalized();
    return SurfaceProjection("plane", ContactSurface::Plane(Vec3(0.2, -0.1, 1.0), 0.03), {NodeRotationAbout(n)});
  }));
  rows.push_back(ProjectionRow("projection_contact_sphere", [] {
    const Vec3 c(0.1, 0.0, -0.5);
    Symmetry about_center{"rotation about the centre",
                          [c](const VectorXd& x, const Mat3& q) -> VectorXd { return c + q * (x - c); },
                          {},
                          {}};
    return SurfaceProjection("sphere", ContactSurface::Sphere(c, 0.5), {about_center});
  }));
  rows.push_back(ProjectionRow("projection_contact_height_field", [] {
    return SurfaceProjection(
        "height field",
        ContactSurface::HeightField(
            [](double x, double y) { return 0.02 * std::sin(5 * x) + 0.01 * x * y; },
            [](double x, double y) { return Eigen::Vector2d(0.1 * std::cos(5 * x) + 0.01 * y, 0.01 * x); }),
        {});
  }));
  for (const bool tets : {false, true}) {
    const std::string el = tets ? "_tet" : "_hex";
    rows.push_back(EnergyRow("elastic_pd" + el, [tets] {
      return ElasticBody(tets, {E::kPdCorotated, E::kPdVolume},
                         tets ? "pd-corotated + pd-volume" : "pd-corotated + pd-volume (fused PD kernel)");
    }));
    rows.push_back(
        EnergyRow("elastic_corotated" + el, [tets] { return ElasticBody(tets, {E::kCorotated}, "corotated"); }));
    rows.push_back(
        EnergyRow("elastic_neohookean" + el, [tets] { return ElasticBody(tets, {E::kNeoHookean}, "neohookean"); }));
    rows.push_back(EnergyRow("elastic_linear" + el, [tets] { return ElasticBody(tets, {E::kLinear}, "linear"); }));
    rows.push_back(EnergyRow("muscle_energy_rest" + el, [tets] { return MuscleEnergy(tets, VectorXd()); }));
    rows.push_back(
        EnergyRow("muscle_energy_active" + el, [tets] { return MuscleEnergy(tets, Eigen::Vector2d(0.8, 1.2)); }));
    rows.push_back(ForceRow("muscle_force" + el, [tets] { return MuscleForce(tets); }));
  }
  rows.push_back(EnergyRow("penalty_contact", [] { return PenaltyEnergy(); }));
  rows.push_back(EnergyRow("auxiliary_energies", [] { return AuxiliaryBody(); }));
  rows.push_back(ForceRow("triangle_drag", [] { return TriangleDrag(); }));
  rows.push_back(
      ForceRow("linear_damping", [] { return StateForceTerm("linear damping", Damped(), {AnyRotation()}); }));
  rows.push_back(
      ForceRow("hydrodynamics", [] { return StateForceTerm("drag and thrust", Swimming(), {AnyRotation()}); }));
  rows.push_back(
      ForceRow("penalty_friction", [] { return StateForceTerm("penalty friction", Sliding(), {RotationAboutZ()}); }));
  rows.push_back(ForceRow("quad_drag", [] { return QuadDrag(); }));
  rows.push_back(ForceRow("quad_hydrodynamics", [] { return QuadStateForceTerm(); }));
  rows.push_back(ForceRow("all_state_forces", [] {
    return StateForceTerm("damping, drag, thrust and friction", AllStateForces(), {RotationAboutZ()});
  }));
  return rows;
}

class EnergyTermsConformanceTest : public ::testing::TestWithParam<Row> {};

TEST_P(EnergyTermsConformanceTest, Conforms) {
  const ConformanceResult result = GetParam().check();
  EXPECT_TRUE(testing::Conforms(result));
  std::cout << result.Describe() << std::endl;  // the term, its property count and smallest margin
}

INSTANTIATE_TEST_SUITE_P(EveryTerm, EnergyTermsConformanceTest, ::testing::ValuesIn(Rows()),
                         [](const ::testing::TestParamInfo<Row>& info) { return Id(info.param.name); });

}  // namespace
}  // namespace diffpd
