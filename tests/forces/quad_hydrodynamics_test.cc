// Quad hydrodynamics (the original swimmers' model): boundary quads of hex
// meshes are outward; a face pushed along its normal feels Cd = 2.05 and
// Ct = 2.5, an oblique one the Bezier values at its angle, a face moving
// away from the water nothing; each corner takes a quarter; the faces the
// water meets are those with a force; the scene checks its inputs. Derivatives: the quad_drag and quad_hydrodynamics
// rows of the conformance test.
#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"
#include "diffpd/scene.h"
#include "diffpd/wetted_quads.h"
#include "forces/quad_hydrodynamic_force.h"
#include "forces/state_forces.h"
#include "test_scenes.h"
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
  internal::StateForces(scene).Add(x, VectorXd::Zero(n), VectorXd::Ones(n), &f);
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
