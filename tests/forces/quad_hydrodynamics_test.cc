// Quad hydrodynamics (the original swimmers' model): boundary quads of hex
// meshes are outward; a face pushed along its normal feels Cd = 2.05 and
// Ct = 2.5, an oblique one the Bezier values at its angle, a face moving
// away from the water nothing; each corner takes a quarter; the faces the
// water meets are those with a force; the scene checks its inputs; a face
// held wet or dry (StepInput::wetted_quads) follows its hold, equals the
// state's force where they agree, and is smooth past grazing incidence;
// holding a rollout's own faces reproduces it bit for bit. Derivatives: the
// quad_drag and quad_hydrodynamics rows of the conformance test.
#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"
#include "diffpd/scene.h"
#include "diffpd/simulator.h"
#include "diffpd/wetted_quads.h"
#include "forces/quad_hydrodynamic_force.h"
#include "forces/state_forces.h"
#include "test_scenes.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

TEST(QuadHydrodynamicsTest, BoundaryQuadsOfAHexBoxAreItsOutwardFaces) {
  const Mesh mesh = testing::BoxHexMesh(2, 1, 1, 0.2, 0.1, 0.1);
  const Eigen::Matrix4Xi quads = BoundaryQuads(mesh);
  ASSERT_EQ(quads.cols(), 10);  // 2 ends, 8 sides; the shared face is inside
  const Vec3 centre(0.1, 0.05, 0.05);
  for (int f = 0; f < quads.cols(); ++f) {
    Vec3 p[4], mid = Vec3::Zero();
    for (int c = 0; c < 4; ++c) {
      p[c] = mesh.vertices.col(quads(c, f));
      mid += p[c] / 4;
    }
    const Vec3 normal = (p[1] - p[0]).cross(p[2] - p[1]);
    EXPECT_NEAR(normal.norm(), 0.01, 1e-15) << "face " << f;  // a 0.1 m square, consecutive corners
    EXPECT_GT(normal.dot(mid - centre), 0) << "face " << f;
  }
  EXPECT_THROW_MESSAGE(BoundaryQuads(testing::BoxTetMesh(1, 1, 1, 0.1, 0.1, 0.1)), InvalidInputError,
                       "BoundaryQuads: the mesh has tet4 elements; quads need hex8");
}

// A 0.1 m square in the xy plane, normal +z.
std::array<Vec3, 4> Square() { return {Vec3(0, 0, 0), Vec3(0.1, 0, 0), Vec3(0.1, 0.1, 0), Vec3(0, 0.1, 0)}; }

TEST(QuadHydrodynamicsTest, FacePushedAlongItsNormalFeelsTheCurvesEndValues) {
  const QuadHydrodynamics water;
  // The face moves at 0.5 m/s along +z: the water's relative velocity is -0.5 z.
  const Vec3 f = internal::QuadHydrodynamicForce(water, Square(), Vec3(0, 0, -0.5));
  // phi = pi/2: Cd = 2.05, Ct = 2.5; f = (rho/2) A |u| (Cd u - Ct |u| n).
  const double expected = 0.5 * 1e3 * 0.01 * 0.5 * (2.05 * -0.5 - 2.5 * 0.5);
  EXPECT_NEAR(f.z(), expected, 1e-12);
  EXPECT_NEAR(f.head<2>().norm(), 0.0, 1e-15);
}

TEST(QuadHydrodynamicsTest, ObliqueFaceFeelsTheBezierValuesAtItsAngle) {
  const QuadHydrodynamics water;
  // Moving at 30 degrees to its plane: phi = pi/6, Cd = B(drag; 1/3) =
  // 14.15/27, Ct = B(thrust; 2/3) = 17.4/27.
  const Vec3 u = -Vec3(std::cos(M_PI / 6), 0, std::sin(M_PI / 6));
  const Vec3 f = internal::QuadHydrodynamicForce(water, Square(), u);
  const Vec3 expected = 0.5 * 1e3 * 0.01 * (14.15 / 27 * u - 17.4 / 27 * Vec3::UnitZ());
  EXPECT_LT((f - expected).norm(), 1e-12);
}

TEST(QuadHydrodynamicsTest, FaceMovingAwayFromTheWaterFeelsNothing) {
  const QuadHydrodynamics water;
  EXPECT_EQ(internal::QuadHydrodynamicForce(water, Square(), Vec3(0.3, 0.1, 0.5)), Vec3::Zero());
  EXPECT_EQ(internal::QuadHydrodynamicForce(water, Square(), Vec3(0.3, 0.1, 0.0)), Vec3::Zero());  // tangential
  std::array<Vec3, 4> g;
  Vec3 g_u;
  QuadHydrodynamicsGradient grad;
  internal::QuadHydrodynamicForceVjp(water, Square(), Vec3(0.3, 0.1, 0.5), Vec3(1, 2, 3), &g, &g_u, &grad);
  EXPECT_EQ(g_u, Vec3::Zero());
  EXPECT_EQ(grad.fluid_density, 0.0);
}

TEST(QuadHydrodynamicsTest, EachCornerTakesAQuarterAndTheFlowCounts) {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(1, 1, 1, 0.1, 0.1, 0.1);
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(scene.mesh);
  water.flow_velocity = Vec3(0, 0, -0.2);
  scene.quad_hydrodynamics = water;
  const int n = scene.mesh.num_dofs();
  VectorXd f = VectorXd::Zero(n);
  const VectorXd x = Eigen::Map<const VectorXd>(scene.mesh.vertices.data(), n);
  // At rest in a flow along -z: only the top face (normal +z) meets it.
  internal::StateForces(scene).Add(x, VectorXd::Zero(n), VectorXd::Ones(n), {}, &f);
  const double total = 0.5 * 1e3 * 0.01 * 0.2 * (2.05 * -0.2 - 2.5 * 0.2);
  for (int i = 0; i < scene.mesh.num_vertices(); ++i) {
    const bool top = scene.mesh.vertices(2, i) > 0.05;
    EXPECT_NEAR(f(3 * i + 2), top ? total / 4 : 0.0, 1e-14) << "node " << i;
  }
}

// The faces the water meets are those whose force is not zero: a box moving
// along +x meets it with its +x face only (the sides move along their own
// planes, the -x face away), a box at rest in still water nowhere, and in a
// current along -x with its +x face too.
TEST(QuadHydrodynamicsTest, WettedQuadsAreTheFacesWithAForce) {
  const Mesh mesh = testing::BoxHexMesh(1, 1, 1, 0.1, 0.1, 0.1);
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(mesh);
  const VectorXd x = Eigen::Map<const VectorXd>(mesh.vertices.data(), mesh.vertices.size());
  VectorXd v = VectorXd::Zero(x.size());
  auto expect_wetted_where_forced = [&](int expected_count) {
    const std::vector<char> wetted = WettedQuads(water, x, v);
    ASSERT_EQ(wetted.size(), 6u);
    int count = 0;
    for (int f = 0; f < 6; ++f) {
      std::array<Vec3, 4> corners;
      Vec3 mean = Vec3::Zero();
      for (int c = 0; c < 4; ++c) {
        corners[c] = x.segment<3>(3 * water.quads(c, f));
        mean += v.segment<3>(3 * water.quads(c, f)) / 4;
      }
      const Vec3 force = internal::QuadHydrodynamicForce(water, corners, water.flow_velocity - mean);
      EXPECT_EQ(wetted[f] != 0, !force.isZero(0)) << "face " << f;
      count += wetted[f];
    }
    EXPECT_EQ(count, expected_count);
  };
  expect_wetted_where_forced(0);
  for (int i = 0; i < mesh.num_vertices(); ++i) v(3 * i) = 0.2;
  expect_wetted_where_forced(1);
  v.setZero();
  water.flow_velocity = Vec3(-0.2, 0, 0);
  expect_wetted_where_forced(1);
}

// The water's velocity relative to the square (normal +z) at angle `phi`
// from its plane (|u| = 0.4 m/s): phi > 0 meets the face, phi < 0 does not.
Vec3 AtAngle(double phi) { return -0.4 * Vec3(std::cos(phi), 0.3 * std::cos(phi), std::sin(phi)).normalized(); }

// A face held dry feels nothing; held wet it feels the state's force
// exactly where the water meets it, and past grazing incidence the wet
// formula continued, without the jump the state's force has there.
TEST(QuadHydrodynamicsTest, AHeldFaceFollowsItsHoldAndEqualsTheStateWhereTheyAgree) {
  const QuadHydrodynamics water;
  using internal::FaceWater;
  for (const double phi : {1.2, 0.5, 1e-3, -1e-3, -0.5, -1.2}) {
    const Vec3 u = AtAngle(phi);
    const Vec3 by_state = internal::QuadHydrodynamicForce(water, Square(), u);
    const Vec3 wet = internal::QuadHydrodynamicForce(water, Square(), u, FaceWater::kHeldWet);
    const Vec3 dry = internal::QuadHydrodynamicForce(water, Square(), u, FaceWater::kHeldDry);
    EXPECT_EQ(dry, Vec3::Zero()) << "phi " << phi;
    EXPECT_EQ(internal::FaceMeetsWater(Square(), u), phi > 0) << "phi " << phi;
    if (phi > 0) {
      EXPECT_EQ(wet, by_state) << "phi " << phi;  // bit for bit
    } else {
      EXPECT_EQ(by_state, Vec3::Zero()) << "phi " << phi;
      EXPECT_GT(wet.norm(), 1e-3) << "phi " << phi;
    }
  }
  const double delta = 1e-9;
  const Vec3 before = internal::QuadHydrodynamicForce(water, Square(), AtAngle(delta));
  const Vec3 held_after = internal::QuadHydrodynamicForce(water, Square(), AtAngle(-delta), FaceWater::kHeldWet);
  EXPECT_GT(before.norm(), 1e-2) << "the state's force jumps at grazing incidence";
  EXPECT_LT((held_after - before).norm(), 1e-6 * before.norm()) << "the held face's does not";
}

// w . F of a face held wet, as a function of its corners and relative
// velocity (15 entries) or of (rho_f, drag curve, thrust curve) (9), past
// grazing incidence: its vector-Jacobian product is the continued formula's
// derivative.
TEST(QuadHydrodynamicsTest, AFaceHeldWetPastGrazingIncidenceHasTheDerivativeOfItsContinuedFormula) {
  const QuadHydrodynamics water;
  const Vec3 w(0.3, -1.1, 0.7);
  for (const double phi : {-0.05, -0.6}) {
    Eigen::Matrix<double, 15, 1> y;
    std::array<Vec3, 4> corners = Square();
    corners[2] += Vec3(0.01, -0.005, 0.008);  // not planar
    for (int c = 0; c < 4; ++c) y.segment<3>(3 * c) = corners[c];
    y.tail<3>() = AtAngle(phi);
    auto geometry_loss = [&](const VectorXd& z) {
      std::array<Vec3, 4> p;
      for (int c = 0; c < 4; ++c) p[c] = z.segment<3>(3 * c);
      return w.dot(internal::QuadHydrodynamicForce(water, p, z.tail<3>(), internal::FaceWater::kHeldWet));
    };
    std::array<Vec3, 4> g_corners;
    Vec3 g_u;
    QuadHydrodynamicsGradient grad;
    internal::QuadHydrodynamicForceVjp(water, corners, y.tail<3>(), w, &g_corners, &g_u, &grad,
                                       internal::FaceWater::kHeldWet);
    EXPECT_FALSE(internal::FaceMeetsWater(corners, y.tail<3>())) << "phi " << phi;
    VectorXd analytic(15);
    for (int c = 0; c < 4; ++c) analytic.segment<3>(3 * c) = g_corners[c];
    analytic.tail<3>() = g_u;
    testing::DifferenceOptions geometry;
    geometry.input_scale = 0.1;  // m, and m/s
    EXPECT_TRUE(testing::Passes(testing::CheckGradient(geometry_loss, y, analytic, geometry))) << "phi " << phi;
    VectorXd theta(9), dtheta(9);
    theta << water.fluid_density, water.drag_curve, water.thrust_curve;
    dtheta << grad.fluid_density, grad.drag_curve, grad.thrust_curve;
    auto parameter_loss = [&](const VectorXd& t) {
      QuadHydrodynamics p = water;
      p.fluid_density = t(0);
      p.drag_curve = t.segment<4>(1);
      p.thrust_curve = t.segment<4>(5);
      return w.dot(internal::QuadHydrodynamicForce(p, corners, y.tail<3>(), internal::FaceWater::kHeldWet));
    };
    EXPECT_TRUE(testing::Passes(testing::CheckGradient(parameter_loss, theta, dtheta))) << "phi " << phi;
  }
}

// A free beam gliding along x through still water: its side faces move
// along their own planes (dry), and any perturbation of v0 turns some into
// the water. Holding each step's faces at the rollout's own reproduces the
// rollout, its gradient and its tangents bit for bit; a perturbed rollout
// left to its state switches faces, one held at the rollout's does not
// feel them, and a wrong hold is refused with its index.
TEST(QuadHydrodynamicsTest, HoldingARolloutsOwnFacesReproducesItBitForBit) {
  Scene scene = testing::SmallBeamScene();
  scene.dirichlet = DirichletBoundary();
  scene.gravity = Vec3::Zero();
  scene.quad_hydrodynamics = QuadHydrodynamics();
  scene.quad_hydrodynamics->quads = BoundaryQuads(scene.mesh);
  const QuadHydrodynamics& water = *scene.quad_hydrodynamics;
  SolverOptions options = testing::TightOptions(Method::kNewtonCholesky);
  options.svd_warm_start = false;  // a step's result depends on its state and input alone
  Simulator sim(scene, options);
  State start = sim.RestState();
  for (int i = 0; i < start.v.size() / 3; ++i) start.v(3 * i) = 0.5;  // m/s
  const int steps = 3, n = sim.num_dofs();
  const Rollout free = sim.Simulate(start, std::vector<StepInput>(steps));
  std::vector<StepInput> held(steps);
  for (int k = 0; k < steps; ++k) held[k].wetted_quads = WettedQuads(water, free.states[k].x, free.states[k].v);
  const Rollout pinned = sim.Simulate(start, held);
  for (int k = 0; k <= steps; ++k) {
    EXPECT_EQ(pinned.states[k].x, free.states[k].x) << "state " << k;
    EXPECT_EQ(pinned.states[k].v, free.states[k].v) << "state " << k;
  }
  LossGradient loss(steps);
  loss.dx[steps] = VectorXd::LinSpaced(n, -1, 1);
  loss.dv[steps] = VectorXd::LinSpaced(n, 0.5, -0.5);
  const RolloutGradient g_free = sim.Backward(free, loss), g_pinned = sim.Backward(pinned, loss);
  EXPECT_EQ(g_pinned.x0, g_free.x0);
  EXPECT_EQ(g_pinned.v0, g_free.v0);
  InputDirection along_v0;
  along_v0.v0 = VectorXd::LinSpaced(n, -0.1, 0.2);
  EXPECT_EQ(sim.Tangents(pinned, {along_v0}).dx[steps], sim.Tangents(free, {along_v0}).dx[steps]);

  State nudged = start;
  nudged.v += 1e-4 * along_v0.v0;
  const Rollout left = sim.Simulate(nudged, std::vector<StepInput>(steps));
  int switched = 0;
  for (int k = 0; k < steps; ++k)
    switched += WettedQuads(water, left.states[k].x, left.states[k].v) != held[k].wetted_quads;
  EXPECT_GT(switched, 0) << "the perturbation turns side faces into the water";
  // The loss's difference quotient along v0: held at the rollout's faces it
  // is that of the piece Backward differentiates; left to the states it
  // measures the jump.
  auto loss_at = [&](double e, const std::vector<StepInput>& inputs) {
    State s = start;
    s.v += e * along_v0.v0;
    const State last = sim.Simulate(s, inputs).states.back();
    return loss.dx[steps].dot(last.x) + loss.dv[steps].dot(last.v);
  };
  const double e = 1e-4, analytic = g_free.v0.dot(along_v0.v0);
  const double held_difference = (loss_at(e, held) - loss_at(-e, held)) / (2 * e);
  const double free_difference =
      (loss_at(e, std::vector<StepInput>(steps)) - loss_at(-e, std::vector<StepInput>(steps))) / (2 * e);
  EXPECT_LT(std::abs(held_difference - analytic), 1e-5 * std::abs(analytic));  // 2e-7 measured
  EXPECT_GT(std::abs(free_difference - analytic), 1e-2 * std::abs(analytic));  // 1.1 measured

  std::vector<StepInput> bad = held;
  bad[2].wetted_quads.pop_back();
  EXPECT_THROW_MESSAGE(sim.Simulate(start, bad), InvalidInputError,
                       "Simulate: inputs[2]: wetted_quads has " + std::to_string(water.quads.cols() - 1) +
                           " entries, expected " + std::to_string(water.quads.cols()) +
                           " (one per quad_hydrodynamics face)");
}

TEST(QuadHydrodynamicsTest, SceneRefusesInvalidQuadHydrodynamics) {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(1, 1, 1, 0.1, 0.1, 0.1);
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(scene.mesh);
  water.quads(3, 5) = 99;
  scene.quad_hydrodynamics = water;
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                       "scene: quad_hydrodynamics.quads(3, 5) = 99 is out of range [0, 8) (no such node)");
  water.quads = BoundaryQuads(scene.mesh);
  water.fluid_density = -1;
  scene.quad_hydrodynamics = water;
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                       "scene: quad_hydrodynamics.fluid_density = -1 is invalid: must be finite and >= 0 (kg/m^3)");
  water.fluid_density = 1e3;
  water.flow_velocity = Vec3(0, INFINITY, 0);
  scene.quad_hydrodynamics = water;
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                       "scene: quad_hydrodynamics.flow_velocity = (0, inf, 0) is invalid: must be finite (m/s)");
  water.flow_velocity = Vec3::Zero();
  water.drag_curve(1) = NAN;
  scene.quad_hydrodynamics = water;
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                       "scene: quad_hydrodynamics.drag_curve = (0.05, nan, 1.85, 2.05) is invalid: must be finite");
  water.drag_curve = QuadHydrodynamics().drag_curve;
  water.thrust_curve(3) = -INFINITY;
  scene.quad_hydrodynamics = water;
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                       "scene: quad_hydrodynamics.thrust_curve = (-0.8, -0.5, 0.1, -inf) is invalid: must be finite");
}

}  // namespace
}  // namespace diffpd
