// The contact, muscle and swimmer-ready problems: rolling-sphere has the
// paper's mesh and initial spin and rolls on its plane; bouncing-ball falls,
// lands without penetrating and rebounds; routing-tendon bends toward its
// contracted muscle; cantilever-plane differs from the cantilever only by its
// inactive plane.
#include <gtest/gtest.h>

#include "scenes/bouncing_ball.h"
#include "scenes/cantilever_plane.h"
#include "diffpd/simulator.h"
#include "problem_registry.h"
#include "scenes/rolling_sphere.h"
#include "scenes/routing_tendon.h"

namespace diffpd {
namespace {

double CenterOfMass(const VectorXd& mass, const VectorXd& x, int axis) {
  double m = 0, c = 0;
  for (int i = 0; i < x.size() / 3; ++i) {
    m += mass(3 * i);
    c += mass(3 * i) * x(3 * i + axis);
  }
  return c / m;
}

TEST(RollingSphereTest, HasThePapersMeshSpinAndContactCandidates) {
  const problems::RollingSphere problem;
  const Scene scene = problem.MakeScene();
  EXPECT_EQ(scene.mesh.num_vertices(), 823);
  EXPECT_EQ(scene.mesh.num_elements(), 552);
  EXPECT_EQ(scene.mesh.num_dofs(), 2469);
  EXPECT_EQ(scene.material.youngs_modulus, 2e6);
  EXPECT_EQ(scene.material.poissons_ratio, 0.4);
  EXPECT_NEAR(scene.mesh.vertices.row(2).minCoeff(), 0.0, 1e-15);
  ASSERT_EQ(scene.frictional_contacts.size(), 1u);
  const Vec3 center = problems::RollingSphere::Center(scene);
  EXPECT_NEAR(center(2), 0.05, 2e-3);
  for (const int i : scene.frictional_contacts[0].nodes) EXPECT_LE(scene.mesh.vertices(2, i), center(2));
  EXPECT_GT(scene.frictional_contacts[0].nodes.size(), 100u);
  // Jittered rest positions: not on the 1 cm grid, by at most 1 mm.
  const double off = scene.mesh.vertices(0, 0) / 0.01 - std::round(scene.mesh.vertices(0, 0) / 0.01);
  EXPECT_NE(off, 0.0);
  Simulator sim(scene, SolverOptions());
  const State s = problem.InitialState(sim);
  for (int i = 0; i < scene.mesh.num_vertices(); i += 50) {
    const Vec3 r = scene.mesh.vertices.col(i) - center;
    EXPECT_LT((s.v.segment<3>(3 * i) - Vec3(0, 10, 0).cross(r)).norm(), 1e-12);
  }
  EXPECT_EQ(problem.default_steps(), 100);
  EXPECT_EQ(problem.default_time_step(), 0.005);
}

TEST(RollingSphereTest, SpinningSphereGripsThePlaneAndStartsToRoll) {
  const problems::RollingSphere problem;
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.time_step = problem.default_time_step();
  options.rel_tolerance = 1e-6;
  Simulator sim(problem.MakeScene(), options);
  State s = problem.InitialState(sim);
  const VectorXd mass = sim.LumpedMass();
  const double x0 = CenterOfMass(mass, s.x, 0);
  StepReport report;
  for (int k = 0; k < 6; ++k) {
    s = sim.Step(s, StepInput(), &report);
    EXPECT_FALSE(report.contact_nodes.empty());
    for (const int i : sim.scene().frictional_contacts[0].nodes) EXPECT_GE(s.x(3 * i + 2), -1e-6);
  }
  // Spin +y over the ground: friction drives the centre toward +x.
  EXPECT_GT(CenterOfMass(mass, s.x, 0) - x0, 1e-4);
}

TEST(BouncingBallTest, FallsLandsWithoutPenetratingAndRebounds) {
  const problems::BouncingBall problem;
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.time_step = problem.default_time_step();
  options.rel_tolerance = 1e-6;
  Simulator sim(problem.MakeScene(), options);
  State s = problem.InitialState(sim);
  const VectorXd mass = sim.LumpedMass();
  double lowest_vz = 0, highest_vz_after = -1;
  bool touched = false;
  StepReport report;
  for (int k = 0; k < 90; ++k) {
    const double z_before = CenterOfMass(mass, s.x, 2);
    s = sim.Step(s, StepInput(), &report);
    const double vz = (CenterOfMass(mass, s.x, 2) - z_before) / options.time_step;
    touched = touched || !report.contact_nodes.empty();
    if (!touched) lowest_vz = std::min(lowest_vz, vz);
    if (touched) highest_vz_after = std::max(highest_vz_after, vz);
    EXPECT_GE(s.x.reshaped(3, s.x.size() / 3).row(2).minCoeff(), -1e-6);
  }
  EXPECT_TRUE(touched);
  EXPECT_LT(lowest_vz, -1.5);        // about 1.7 m/s at impact
  EXPECT_GT(highest_vz_after, 0.1);  // it bounces back up
}

TEST(RoutingTendonTest, ContractingTheXMuscleBendsTheColumnTowardX) {
  const problems::RoutingTendon problem;
  const Scene scene = problem.MakeScene();
  EXPECT_EQ(scene.mesh.num_dofs(), 624);
  ASSERT_EQ(scene.muscles.size(), 4u);
  for (const Muscle& m : scene.muscles) EXPECT_EQ(m.elements.size(), 36u);
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.time_step = problem.default_time_step();
  Simulator sim(scene, options);
  const std::vector<StepInput> inputs = problem.Inputs(sim, 20);
  EXPECT_NEAR(inputs.back().activation(0), 0.8, 1e-12);  // the ramp spans the rollout
  EXPECT_NEAR(inputs.back().activation(1), 1.0, 0.0);
  const Rollout r = sim.Simulate(sim.RestState(), inputs);
  double dx = 0;
  const std::vector<int> tip = problems::RoutingTendon::TipNodes(scene);
  ASSERT_EQ(tip.size(), 16u);
  for (const int i : tip) dx += (r.states.back().x(3 * i) - scene.mesh.vertices(0, i)) / tip.size();
  EXPECT_GT(dx, 2e-3);
}

TEST(CantileverPlaneTest, IsTheCantileverWithAnInactivePlane) {
  const problems::Cantilever plain(8, 2, 2);
  const problems::CantileverWithPlane with_plane(8, 2, 2);
  const Scene a = plain.MakeScene(), b = with_plane.MakeScene();
  EXPECT_TRUE(a.frictional_contacts.empty());
  ASSERT_EQ(b.frictional_contacts.size(), 1u);
  EXPECT_EQ(b.frictional_contacts[0].nodes.size() + a.dirichlet.dofs.size() / 3,
            static_cast<size_t>(a.mesh.num_vertices()));
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  Simulator sa(a, options), sb(b, options);
  const Rollout ra = sa.Simulate(plain.InitialState(sa), std::vector<StepInput>(3));
  const Rollout rb = sb.Simulate(with_plane.InitialState(sb), std::vector<StepInput>(3));
  EXPECT_EQ((ra.states.back().x - rb.states.back().x).norm(), 0.0);
  EXPECT_NE(problems::MakeProblem("cantilever-plane"), nullptr);
}

}  // namespace
}  // namespace diffpd
