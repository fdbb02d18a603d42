// Explicit state forces (linear damping, hydrodynamic drag and thrust,
// penalty friction): vector-Jacobian products vs finite differences, boundary
// triangles, physical behaviour, and rollout gradients w.r.t. the state and
// the force parameters for PD and Newton.
#include <gtest/gtest.h>

#include <random>

#include "diffpd/simulator.h"
#include "diffpd/state_forces.h"
#include "fem/fem_model.h"
#include "forces/state_forces.h"
#include "tools/gradcheck.h"
#include "test_scenes.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

VectorXd Random(int n, std::mt19937_64* rng, double scale = 1.0) {
  std::normal_distribution<double> normal(0.0, scale);
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

// A free 2x2x2 box swimming in a current, damped, sliding on a penalty floor.
Scene SwimmerScene(bool tets = false) {
  Scene scene;
  scene.mesh = tets ? testing::BoxTetMesh(2, 2, 1, 0.1, 0.1, 0.05) : testing::BoxHexMesh(2, 2, 1, 0.1, 0.1, 0.05);
  scene.material.youngs_modulus = 1e5;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 800;
  scene.gravity = Vec3(0, 0, -9.81);
  Hydrodynamics hydro;
  hydro.triangles = BoundaryTriangles(scene.mesh);
  hydro.thrust = 0.6;
  hydro.flow_velocity = Vec3(0.1, -0.05, 0.02);
  scene.hydrodynamics = hydro;
  scene.linear_damping = 0.5;
  PenaltyContact floor;
  floor.offset = 0.002;  // the bottom nodes start 2 mm inside
  floor.stiffness = 200;
  floor.friction = 0.4;
  floor.friction_velocity = 0.05;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) < 1e-9) floor.nodes.push_back(i);
  scene.penalty_contacts = {floor};
  return scene;
}

TEST(BoundaryTrianglesTest, CoverTheBoundaryOnceAndPointOutward) {
  for (const bool tets : {false, true}) {
    const Mesh mesh = tets ? testing::BoxTetMesh(2, 3, 1, 0.2, 0.3, 0.1) : testing::BoxHexMesh(2, 3, 1, 0.2, 0.3, 0.1);
    const Eigen::Matrix3Xi tri = BoundaryTriangles(mesh);
    // 2 (2*3 + 2*1 + 3*1) quads, each 2 triangles.
    EXPECT_EQ(tri.cols(), 2 * 2 * (6 + 2 + 3));
    double volume = 0, area = 0;
    Vec3 total = Vec3::Zero();
    for (int t = 0; t < tri.cols(); ++t) {
      const Vec3 a = mesh.vertices.col(tri(0, t)), b = mesh.vertices.col(tri(1, t)), c = mesh.vertices.col(tri(2, t));
      volume += a.dot(b.cross(c)) / 6.0;  // divergence theorem: positive iff outward
      total += 0.5 * (b - a).cross(c - a);
      area += 0.5 * (b - a).cross(c - a).norm();
    }
    EXPECT_NEAR(volume, 0.2 * 0.3 * 0.1, 1e-12);
    EXPECT_NEAR(area, 2 * (0.2 * 0.3 + 0.2 * 0.1 + 0.3 * 0.1), 1e-12);
    EXPECT_LT(total.norm(), 1e-12);
    EXPECT_EQ(BoundaryNodes(mesh).size(), 3u * 4u * 2u);  // every node of a 2x3x1 grid is on the boundary
  }
  EXPECT_EQ(BoundaryNodes(testing::BoxHexMesh(3, 3, 3, 1, 1, 1)).size(), 64u - 8u);
}

TEST(StateForcesTest, VectorJacobianProductsMatchFiniteDifferences) {
  const Scene scene = SwimmerScene();
  internal::FemModel fem(scene.mesh);
  internal::StateForces forces(scene);
  const int n = scene.mesh.num_dofs();
  std::mt19937_64 rng(4);
  VectorXd unit_mass(n);
  for (int i = 0; i < n / 3; ++i) unit_mass.segment<3>(3 * i).setConstant(fem.unit_lumped_mass()(i));
  const double rho = scene.material.density;
  const VectorXd mass = rho * unit_mass;
  for (int trial = 0; trial < 3; ++trial) {
    VectorXd x = Eigen::Map<const VectorXd>(scene.mesh.vertices.data(), n) + Random(n, &rng, 0.003);
    const VectorXd v = Random(n, &rng, 0.2);
    const VectorXd w = Random(n, &rng);
    VectorXd gx = VectorXd::Zero(n), gv = VectorXd::Zero(n);
    StateForceGradient grad;
    VectorXd dmass = VectorXd::Zero(n);
    forces.AddVjp(x, v, mass, {}, w, &gx, &gv, &grad, &dmass);
    const double drho = dmass.dot(unit_mass);  // M = rho m
    auto wf = [&](const VectorXd& xx, const VectorXd& vv, double r) {
      VectorXd f = VectorXd::Zero(n);
      forces.Add(xx, vv, r * unit_mass, {}, &f);
      return w.dot(f);
    };
    const VectorXd dx = Random(n, &rng), dv = Random(n, &rng);
    const auto wf_x = [&](const VectorXd& xx) { return wf(xx, v, rho); };
    const auto wf_v = [&](const VectorXd& vv) { return wf(x, vv, rho); };
    const auto wf_rho = [&](const VectorXd& r) { return wf(x, v, r(0)); };
    const VectorXd one = VectorXd::Ones(1);
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(wf_x, x, dx, gx.dot(dx)))) << "x";
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(wf_v, v, dv, gv.dot(dv)))) << "v";
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(wf_rho, VectorXd::Constant(1, rho), one, drho)))
        << "density";
    // Parameters: w . F as a function of one scene field.
    auto check_param = [&](const std::function<double&(Scene&)>& field, double analytic, const char* name) {
      Scene base = scene;
      const auto wf_param = [&](const VectorXd& p) {
        Scene s = scene;
        field(s) = p(0);
        VectorXd f = VectorXd::Zero(n);
        internal::StateForces(s).Add(x, v, mass, {}, &f);
        return w.dot(f);
      };
      EXPECT_TRUE(testing::Passes(
          testing::CheckDirectionalDerivative(wf_param, VectorXd::Constant(1, field(base)), one, analytic)))
          << name;
    };
    check_param([](Scene& s) -> double& { return *s.linear_damping; }, grad.linear_damping, "linear_damping");
    check_param([](Scene& s) -> double& { return s.hydrodynamics->fluid_density; }, grad.fluid_density,
                "fluid_density");
    check_param([](Scene& s) -> double& { return s.hydrodynamics->drag_normal; }, grad.drag_normal, "drag_normal");
    check_param([](Scene& s) -> double& { return s.hydrodynamics->drag_tangential; }, grad.drag_tangential,
                "drag_tangential");
    check_param([](Scene& s) -> double& { return s.hydrodynamics->thrust; }, grad.thrust, "thrust");
    check_param([](Scene& s) -> double& { return s.hydrodynamics->flow_velocity(1); }, grad.flow_velocity(1),
                "flow_velocity(1)");
    check_param([](Scene& s) -> double& { return s.penalty_contacts[0].friction; }, grad.penalty_friction[0],
                "penalty_contacts[0].friction");
  }
}

TEST(StateForcesTest, LinearDampingDecaysTheVelocityOfAFreeBodyAtItsRate) {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(2, 2, 2, 0.1, 0.1, 0.1);
  scene.linear_damping = 2.0;
  SolverOptions options;
  options.method = Method::kPd;
  options.time_step = 0.01;
  options.rel_tolerance = 1e-10;
  Simulator sim(scene, options);
  State s = sim.RestState();
  s.v = VectorXd::Constant(sim.num_dofs(), 0.3);
  // Rigid translation: v_{i+1} = v_i + h (-c v_i) (explicit damping force).
  for (int k = 1; k <= 10; ++k) {
    s = sim.Step(s, StepInput());
    EXPECT_NEAR(s.v(0), 0.3 * std::pow(1 - 0.01 * 2.0, k), 1e-9);
  }
}

TEST(StateForcesTest, SceneWithoutStateForcesIsUnchangedByTheMachinery) {
  const Scene plain = testing::SmallBeamScene();
  Scene zero = plain;
  zero.linear_damping = 0.0;
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  Simulator a(plain, options), b(zero, options);
  const Rollout ra = a.Simulate(a.RestState(), std::vector<StepInput>(3));
  const Rollout rb = b.Simulate(b.RestState(), std::vector<StepInput>(3));
  EXPECT_EQ((ra.states.back().x - rb.states.back().x).norm(), 0.0);
}

class StateForceGradientTest : public ::testing::TestWithParam<Method> {};

TEST_P(StateForceGradientTest, RolloutGradientsWithRespectToStateAndForceParametersMatchFiniteDifferences) {
  const Scene scene = SwimmerScene();
  SolverOptions options;
  options.method = GetParam();
  options.time_step = 0.004;
  options.rel_tolerance = 1e-12;
  options.abs_tolerance = 1e-11;
  options.backward_rel_tolerance = 1e-13;
  options.max_iterations = 20000;
  options.num_threads = 1;
  Simulator sim(scene, options);
  State initial = sim.RestState();
  std::mt19937_64 rng(8);
  initial.v = Random(sim.num_dofs(), &rng, 0.5);
  const problems::GradCheckResult result = problems::CheckRolloutGradient(scene, options, initial, 3);
  int parameters = 0;
  for (const auto& entry : result.inputs) {
    EXPECT_EQ(entry.verdict, problems::CheckVerdict::kPass)
        << ToString(GetParam()) << " input " << entry.input << ": " << entry.reason;
    EXPECT_GE(entry.margin, 10.0) << ToString(GetParam()) << " input " << entry.input;  // error and floor <= 1e-5
    for (const char* name :
         {"linear_damping", "fluid_density", "drag_tangential", "drag_normal", "thrust", "penalty_friction"})
      if (entry.input == name) ++parameters;
  }
  EXPECT_EQ(parameters, 6);
}

INSTANTIATE_TEST_SUITE_P(Methods, StateForceGradientTest, ::testing::Values(Method::kPd, Method::kNewtonCholesky),
                         [](const ::testing::TestParamInfo<Method>& info) {
                           return info.param == Method::kPd ? std::string("pd") : std::string("newton_cholesky");
                         });

}  // namespace
}  // namespace diffpd
