// Forward-mode tangents (Simulator::Tangents) vs central finite differences
// of whole rollouts and vs reverse mode (Backward), for every method, on
// small hex and tet beams, with and without explicit state forces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <random>

#include "diffpd/box_mesh.h"
#include "diffpd/error.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/state_forces.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"
#include "util/expect_message.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

using testing::MovingStart;
using testing::RandomVector;
using testing::TightOptions;

struct Case {
  Method method;
  bool tets;
};

// Directions: E, nu, rho (scaled to the parameter), x0, v0, forces, and a mix.
std::vector<InputDirection> TestDirections(const Scene& scene, int n, int steps) {
  std::mt19937_64 rng(7);
  std::vector<InputDirection> dirs;
  InputDirection e = InputDirection::YoungsModulus();
  e.youngs_modulus = scene.material.youngs_modulus;
  dirs.push_back(e);
  dirs.push_back(InputDirection::PoissonsRatio());
  InputDirection rho = InputDirection::Density();
  rho.density = scene.material.density;
  dirs.push_back(rho);
  InputDirection x0;
  x0.x0 = RandomVector(n, &rng, 1e-2);
  dirs.push_back(x0);
  InputDirection v0;
  v0.v0 = RandomVector(n, &rng, 0.1);
  dirs.push_back(v0);
  InputDirection f;
  for (int k = 0; k < steps; ++k) f.external_force.push_back(k == 1 ? VectorXd() : RandomVector(n, &rng, 1.0));
  dirs.push_back(f);
  InputDirection mix = e;
  mix.poissons_ratio = 0.5;
  mix.v0 = v0.v0;
  dirs.push_back(mix);
  return dirs;
}

// The rollout at inputs moved by eps along d.
Rollout Perturbed(const Scene& scene, const SolverOptions& options, const State& start, int steps,
                  const InputDirection& d, double eps) {
  Scene s = scene;
  s.material.youngs_modulus += eps * d.youngs_modulus;
  s.material.poissons_ratio += eps * d.poissons_ratio;
  s.material.density += eps * d.density;
  Simulator sim(s, options);
  State init = start;
  if (d.x0.size()) init.x += eps * d.x0;
  if (d.v0.size()) init.v += eps * d.v0;
  std::vector<StepInput> inputs(steps);
  for (int k = 0; k < steps; ++k)
    if (!d.external_force.empty() && d.external_force[k].size()) inputs[k].external_force = eps * d.external_force[k];
  return sim.Simulate(init, inputs);
}

std::string CaseName(const ::testing::TestParamInfo<Case>& info) {
  std::string name = ToString(info.param.method);
  for (char& ch : name)
    if (ch == '-') ch = '_';
  return name + (info.param.tets ? "_tet" : "_hex");
}

class TangentFiniteDifferenceTest : public ::testing::TestWithParam<Case> {};
class TangentReverseModeTest : public ::testing::TestWithParam<Case> {};

TEST_P(TangentFiniteDifferenceTest, MatchesCentralFiniteDifferencesOfEveryState) {
  const Case c = GetParam();
  const Scene scene = testing::SmallBeamScene(c.tets);
  const SolverOptions options = TightOptions(c.method);
  Simulator sim(scene, options);
  const State start = MovingStart(sim);
  const int steps = c.method == Method::kSemiImplicit ? 20 : 4;
  const Rollout rollout = sim.Simulate(start, std::vector<StepInput>(steps));
  const std::vector<InputDirection> dirs = TestDirections(scene, sim.num_dofs(), steps);
  const TangentRollout t = sim.Tangents(rollout, dirs);
  ASSERT_EQ(t.num_steps(), steps);
  ASSERT_EQ(t.num_directions(), static_cast<int>(dirs.size()));
  for (size_t p = 0; p < dirs.size(); ++p) {
    // The step rule for states solved to rel_tolerance: eps = cbrt(1e-12)
    // times the input scale, 1 for the directions scaled to their inputs,
    // and for Poisson's ratio the distance 0.5 - nu to the pole of lambda
    // over its share of the direction.
    const double nu_scale = (0.5 - scene.material.poissons_ratio) / std::abs(dirs[p].poissons_ratio);
    const double eps = testing::CentralDifferenceStep(options.rel_tolerance, std::min(1.0, nu_scale));
    const Rollout plus = Perturbed(scene, options, start, steps, dirs[p], eps);
    const Rollout minus = Perturbed(scene, options, start, steps, dirs[p], -eps);
    // Relative to the largest state tangent of the direction (early steps
    // can be tiny, e.g. x_1 under a force with a small time step), with no
    // absolute floor: the solves converge far below their tolerance here.
    testing::DifferenceOptions x_options, v_options;
    x_options.noise = v_options.noise = options.rel_tolerance;
    x_options.floor = v_options.floor = 0;
    x_options.rtol = 1e-6;
    // v = (x_{k} - x_{k-1}) / h amplifies the forward solves' residual by
    // 1/h, so the velocity differences carry about 3x the noise of x.
    v_options.rtol = 3e-6;
    for (int k = 1; k <= steps; ++k) {
      x_options.derivative_scale = std::max(x_options.derivative_scale, t.dx[k].col(p).norm());
      v_options.derivative_scale = std::max(v_options.derivative_scale, t.dv[k].col(p).norm());
    }
    ASSERT_GT(x_options.derivative_scale, 0.0);
    for (int k = 1; k <= steps; ++k) {
      EXPECT_TRUE(testing::Passes(
          testing::CompareCentralDifference(plus.states[k].x, minus.states[k].x, eps, t.dx[k].col(p), x_options)))
          << ToString(c.method) << " direction " << p << " x_" << k;
      EXPECT_TRUE(testing::Passes(
          testing::CompareCentralDifference(plus.states[k].v, minus.states[k].v, eps, t.dv[k].col(p), v_options)))
          << ToString(c.method) << " direction " << p << " v_" << k;
    }
  }
}

TEST_P(TangentReverseModeTest, AgreesWithReverseModeOnRandomLinearLosses) {
  const Case c = GetParam();
  const Scene scene = testing::SmallBeamScene(c.tets);
  const SolverOptions options = TightOptions(c.method);
  Simulator sim(scene, options);
  const int n = sim.num_dofs();
  const int steps = c.method == Method::kSemiImplicit ? 20 : 4;
  const Rollout rollout = sim.Simulate(MovingStart(sim), std::vector<StepInput>(steps));
  const std::vector<InputDirection> dirs = TestDirections(scene, n, steps);
  const TangentRollout t = sim.Tangents(rollout, dirs);
  // L = sum_k cx_k . x_k + cv_k . v_k with random weights on every state.
  std::mt19937_64 rng(11);
  LossGradient loss(steps);
  for (int k = 0; k <= steps; ++k) {
    loss.dx[k] = RandomVector(n, &rng, 1.0);
    loss.dv[k] = RandomVector(n, &rng, 0.01);
  }
  const RolloutGradient g = sim.Backward(rollout, loss);
  for (size_t p = 0; p < dirs.size(); ++p) {
    double forward = 0;
    for (int k = 0; k <= steps; ++k) forward += loss.dx[k].dot(t.dx[k].col(p)) + loss.dv[k].dot(t.dv[k].col(p));
    const InputDirection& d = dirs[p];
    double reverse = g.youngs_modulus * d.youngs_modulus + g.poissons_ratio * d.poissons_ratio + g.density * d.density;
    if (d.x0.size()) reverse += g.x0.dot(d.x0);
    if (d.v0.size()) reverse += g.v0.dot(d.v0);
    for (int k = 0; k < steps && !d.external_force.empty(); ++k)
      if (d.external_force[k].size()) reverse += g.external_force[k].dot(d.external_force[k]);
    EXPECT_NEAR(forward, reverse, 1e-8 * std::abs(reverse)) << ToString(c.method) << " direction " << p;
  }
}

// Finite differences need tightly converged forward solves, slow for PD on
// hexes (8 samples per element): PD is checked on tets here and on hexes
// against reverse mode below.
INSTANTIATE_TEST_SUITE_P(AllMethods, TangentFiniteDifferenceTest,
                         ::testing::Values(Case{Method::kSemiImplicit, false}, Case{Method::kNewtonCholesky, false},
                                           Case{Method::kNewtonPcg, false}, Case{Method::kPdLbfgs, false},
                                           Case{Method::kNewtonCholesky, true}, Case{Method::kPd, true}),
                         CaseName);
INSTANTIATE_TEST_SUITE_P(AllMethods, TangentReverseModeTest,
                         ::testing::Values(Case{Method::kSemiImplicit, false}, Case{Method::kNewtonCholesky, false},
                                           Case{Method::kNewtonPcg, false}, Case{Method::kPd, false},
                                           Case{Method::kPdLbfgs, false}, Case{Method::kNewtonCholesky, true},
                                           Case{Method::kPd, true}),
                         CaseName);

// Stiff, nearly incompressible material (E = 1e10 Pa, nu = 0.499: lambda =
// 1.7e12 Pa) on a free cell released squashed: after one step of 0.1 s the
// volumetric strain left is about stress / lambda ~ 1e-11, near the rounding
// of F (~1e-16), so the pd-volume stress sigma - d is known to only ~1e-5
// relative and the Poisson's ratio derivative, which is nearly all lambda
// term (dlambda/dnu = 1.7e15 Pa), inherits that. Reverse and forward mode
// must read the same unit-Lame stresses to stay exact transposes of one
// linearisation: with Newton-Cholesky both solve with one factor, so they
// agree to ~1e-7 (the factor's rounding at a condition number of ~1e10);
// evaluated each its own way they differed by up to 9e-5 on these inputs.
TEST(TangentRolloutTest, MaterialTangentsTransposeReverseModeForStiffNearlyIncompressibleMaterial) {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(1, 1, 1), Vec3(0.1, 0.1, 0.1));
  scene.material.youngs_modulus = 1e10;
  scene.material.poissons_ratio = 0.499;
  scene.material.density = 1e3;
  scene.gravity = Vec3(0, 0, -9.81);
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  options.time_step = 0.1;
  options.rel_tolerance = 1e-12;
  options.abs_tolerance = 1e-14;
  options.num_threads = 1;
  for (std::uint64_t seed : {1, 2, 3}) {
    Simulator sim(scene, options);
    const int n = sim.num_dofs();
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal;
    VectorXd cx(n), cv(n), force(n);
    const double node_weight = 0.125 * 9.81;  // N: a corner's share of the 1 kg cell
    for (int i = 0; i < n; ++i) {
      cx(i) = normal(rng);
      cv(i) = normal(rng);
      force(i) = 0.1 * node_weight * normal(rng);
    }
    State start = sim.RestState();
    for (int i = 0; i < n / 3; ++i) start.x(3 * i + 2) *= 0.9;
    std::vector<StepInput> inputs(1);
    inputs[0].external_force = force;
    const Rollout rollout = sim.Simulate(start, inputs);
    LossGradient loss(1);
    loss.dx[1] = cx;
    loss.dv[1] = cv;
    const RolloutGradient g = sim.Backward(rollout, loss);
    const TangentRollout t = sim.Tangents(rollout, {InputDirection::PoissonsRatio(), InputDirection::YoungsModulus()});
    const double nu_forward = cx.dot(t.dx[1].col(0)) + cv.dot(t.dv[1].col(0));
    const double e_forward = cx.dot(t.dx[1].col(1)) + cv.dot(t.dv[1].col(1));
    EXPECT_NEAR(g.poissons_ratio, nu_forward, 1e-6 * std::abs(nu_forward)) << "seed " << seed;
    EXPECT_NEAR(g.youngs_modulus, e_forward, 1e-6 * std::abs(e_forward)) << "seed " << seed;
  }
}

TEST(TangentRolloutTest, PdReusesTheForwardFactorForEveryColumn) {
  // CG (the default PD backward) and L-BFGS converge without a direct
  // fallback; the DiffPD fixed point A z_{k+1} = b + dA z_k contracts too
  // slowly on this scene and falls back, exactly like the adjoint; all give
  // the same tangents.
  SolverOptions options = TightOptions(Method::kPd);
  const std::vector<InputDirection> dirs = {InputDirection::YoungsModulus(), InputDirection::PoissonsRatio(),
                                            InputDirection::Density()};
  std::vector<MatrixXd> last;
  for (PdBackwardMethod backward :
       {PdBackwardMethod::kConjugateGradient, PdBackwardMethod::kLbfgs, PdBackwardMethod::kFixedPoint}) {
    options.pd_backward = backward;
    Simulator sim(testing::SmallBeamScene(), options);
    const Rollout rollout = sim.Simulate(MovingStart(sim), std::vector<StepInput>(3));
    const int factorizations = sim.num_pd_factorizations();
    const TangentRollout t = sim.Tangents(rollout, dirs);
    EXPECT_EQ(sim.num_pd_factorizations(), factorizations);
    EXPECT_GT(t.report.linear_iterations, 0);
    LossGradient loss(3);
    loss.dx[3] = VectorXd::Ones(sim.num_dofs());
    const RolloutGradient g = sim.Backward(rollout, loss);
    EXPECT_EQ(t.report.fallbacks, static_cast<int>(dirs.size()) * g.report.fallbacks);
    if (backward != PdBackwardMethod::kFixedPoint) {
      EXPECT_EQ(t.report.fallbacks, 0);
    }
    last.push_back(t.dx.back());
  }
  EXPECT_LT((last[0] - last[1]).norm(), 1e-8 * last[0].norm());
  EXPECT_LT((last[0] - last[2]).norm(), 1e-8 * last[0].norm());
}

TEST(TangentRolloutTest, SeveralColumnsEqualOneColumnAtATime) {
  Simulator sim(testing::SmallBeamScene(), TightOptions(Method::kPd));
  const Rollout rollout = sim.Simulate(MovingStart(sim), std::vector<StepInput>(3));
  const std::vector<InputDirection> dirs = {InputDirection::YoungsModulus(), InputDirection::PoissonsRatio(),
                                            InputDirection::Density()};
  const TangentRollout all = sim.Tangents(rollout, dirs);
  for (size_t p = 0; p < dirs.size(); ++p) {
    const TangentRollout one = sim.Tangents(rollout, {dirs[p]});
    EXPECT_LT((one.dx.back().col(0) - all.dx.back().col(p)).norm(), 1e-10 * one.dx.back().norm());
  }
}

TEST(TangentRolloutTest, FixedDofsHaveZeroPositionTangent) {
  Simulator sim(testing::SmallBeamScene(), TightOptions(Method::kNewtonCholesky));
  const Rollout rollout = sim.Simulate(MovingStart(sim), std::vector<StepInput>(2));
  const TangentRollout t = sim.Tangents(rollout, {InputDirection::YoungsModulus()});
  for (int dof : sim.scene().dirichlet.dofs) {
    EXPECT_EQ(t.dx[1](dof, 0), 0.0);
    EXPECT_EQ(t.dx[2](dof, 0), 0.0);
  }
  EXPECT_GT(t.dx[2].norm(), 0.0);
}

TEST(TangentRolloutTest, RejectsBadDirectionsWithMessages) {
  Simulator sim(testing::SmallBeamScene(), TightOptions(Method::kPd));
  const Rollout rollout = sim.Simulate(sim.RestState(), std::vector<StepInput>(2));
  auto message = [&](const std::vector<InputDirection>& dirs) {
    return testing::MessageOf<InvalidInputError>([&] { sim.Tangents(rollout, dirs); });
  };
  EXPECT_EQ(message({}), "Tangents: no direction given (need at least one)");
  InputDirection bad;
  bad.x0 = VectorXd::Ones(5);
  EXPECT_EQ(message({InputDirection::Density(), bad}), "Tangents: direction 1 has x0 with 5 entries, expected " +
                                                           std::to_string(sim.num_dofs()) + " (3 x number of nodes)");
  InputDirection forces;
  forces.external_force.resize(3);
  EXPECT_EQ(message({forces}), "Tangents: direction 0 has external_force for 3 steps, expected 0 or 2");
  InputDirection nan = InputDirection::YoungsModulus();
  nan.v0 = VectorXd::Zero(sim.num_dofs());
  nan.v0(4) = std::nan("");
  EXPECT_EQ(message({nan}), "Tangents: direction 0 has a non-finite entry in v0");
  sim.SetMaterial(MaterialParameters{3e5, 0.4, 1e3});
  EXPECT_EQ(message({InputDirection::Density()}),
            "Tangents: the rollout was made with another material (E = 200000 Pa, nu = 0.4, rho = 1000 kg/m^3) than "
            "the simulator's current one (E = 300000 Pa, nu = 0.4, rho = 1000 kg/m^3)");
}

// A small box (2 x 2 x 2 hexes, 4 cm) dropped onto the plane z = 0 with a
// sideways velocity: its bottom nodes touch during the rollout.
Scene DroppedBoxScene() {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(2, 2, 2), Vec3(0.04, 0.04, 0.04), Vec3(0, 0, 0.002));
  scene.material = MaterialParameters{1e5, 0.4, 1e3};
  scene.gravity = Vec3(0, 0, -9.81);
  FrictionalContact contact;
  contact.surface = ContactSurface::Plane(Vec3(0, 0, 1), 0.0);
  contact.nodes = BoundaryNodes(scene.mesh);
  scene.frictional_contacts = {contact};
  return scene;
}

// Tangents through frictional contact (active set held fixed, pins
// differentiated) vs reverse mode and central differences; the differences
// stay on the same piece of the trajectory (same active sets).
TEST(TangentRolloutTest, FrictionalContactTangentsMatchReverseModeAndFiniteDifferences) {
  const Scene scene = DroppedBoxScene();
  for (Method method : {Method::kNewtonCholesky, Method::kPd}) {
    SolverOptions options = TightOptions(method);
    options.time_step = 0.005;
    Simulator sim(scene, options);
    State start = sim.RestState();
    for (int i = 0; i < start.v.size() / 3; ++i) start.v.segment<3>(3 * i) = Vec3(0.3, 0.1, -0.5);
    const int steps = 6;
    const Rollout rollout = sim.Simulate(start, std::vector<StepInput>(steps));
    int contact_steps = 0;
    for (const StepReport& r : rollout.reports) contact_steps += !r.contact_nodes.empty();
    ASSERT_GE(contact_steps, 3) << ToString(method);
    InputDirection e = InputDirection::YoungsModulus();
    e.youngs_modulus = scene.material.youngs_modulus;
    InputDirection v0;
    v0.v0 = VectorXd::Zero(sim.num_dofs());
    for (int i = 0; i < sim.num_dofs() / 3; ++i) v0.v0.segment<3>(3 * i) = Vec3(0.1, -0.2, 0.05);
    InputDirection x0;
    x0.x0 = 0.1 * v0.v0;
    const std::vector<InputDirection> dirs = {e, v0, x0};
    const TangentRollout t = sim.Tangents(rollout, dirs);
    LossGradient loss(steps);
    std::mt19937_64 rng(5);
    loss.dx[steps] = RandomVector(sim.num_dofs(), &rng, 1.0);
    loss.dv[steps - 2] = RandomVector(sim.num_dofs(), &rng, 0.01);
    const RolloutGradient g = sim.Backward(rollout, loss);
    const double reverse[3] = {g.youngs_modulus * e.youngs_modulus, g.v0.dot(v0.v0), g.x0.dot(x0.x0)};
    for (int p = 0; p < 3; ++p) {
      const double forward = loss.dx[steps].dot(t.dx[steps].col(p)) + loss.dv[steps - 2].dot(t.dv[steps - 2].col(p));
      EXPECT_NEAR(forward, reverse[p], 1e-8 * std::abs(reverse[p])) << ToString(method) << " direction " << p;
      // A step of 1e-6 (not the rule's 1e-4) keeps the perturbed rollouts on
      // the same active sets.
      const double eps = 1e-6;
      const Rollout plus = Perturbed(scene, options, start, steps, dirs[p], eps);
      const Rollout minus = Perturbed(scene, options, start, steps, dirs[p], -eps);
      for (int k = 0; k < steps; ++k) ASSERT_EQ(plus.reports[k].contact_nodes, rollout.reports[k].contact_nodes);
      // Central differences carry the forward solves' rounding / eps, about
      // 1e-15 m / 1e-6 = 1e-9 m per unit, which matters where the pinned
      // contact nodes make the final state almost insensitive to v0: the
      // test's own floor 5e-9.
      testing::DifferenceOptions check;
      check.noise = options.rel_tolerance;
      check.floor = 5e-9;
      EXPECT_TRUE(testing::Passes(testing::CompareCentralDifference(plus.states[steps].x, minus.states[steps].x, eps,
                                                                    t.dx[steps].col(p), check)))
          << ToString(method) << " direction " << p;
    }
  }
}

// Tangents along per-step muscle activations vs central differences.
TEST(TangentRolloutTest, ActivationTangentsMatchFiniteDifferences) {
  Scene scene = testing::SmallBeamScene();
  Muscle muscle;
  for (int e = 0; e < scene.mesh.num_elements(); e += 2) muscle.elements.push_back(e);
  muscle.fibers = {Vec3(1, 0, 0)};
  muscle.stiffness = 3e5;
  scene.muscles = {muscle};
  const int steps = 4;
  for (Method method : {Method::kNewtonCholesky, Method::kSemiImplicit}) {
    SolverOptions options = TightOptions(method);
    const int k_steps = method == Method::kSemiImplicit ? 20 : steps;
    Simulator sim(scene, options);
    std::vector<StepInput> inputs(k_steps);
    for (int k = 0; k < k_steps; ++k) inputs[k].activation = VectorXd::Constant(1, 0.9 - 0.01 * k);
    const Rollout rollout = sim.Simulate(MovingStart(sim), inputs);
    InputDirection d;
    for (int k = 0; k < k_steps; ++k)
      d.activation.push_back(k == 1 ? VectorXd() : VectorXd::Constant(1, 0.5 + 0.1 * k));
    const TangentRollout t = sim.Tangents(rollout, {d, InputDirection::PoissonsRatio()});
    const double eps = 1e-6;
    std::vector<StepInput> plus = inputs, minus = inputs;
    for (int k = 0; k < k_steps; ++k)
      if (d.activation[k].size()) {
        plus[k].activation += eps * d.activation[k];
        minus[k].activation -= eps * d.activation[k];
      }
    const VectorXd x_plus = sim.Simulate(MovingStart(sim), plus).states.back().x;
    const VectorXd x_minus = sim.Simulate(MovingStart(sim), minus).states.back().x;
    EXPECT_GT((x_plus - x_minus).norm(), 0.0);
    testing::DifferenceOptions check;
    check.noise = options.rel_tolerance;
    check.floor = 0;  // the test's own: relative to the tangent only
    EXPECT_TRUE(testing::Passes(testing::CompareCentralDifference(x_plus, x_minus, eps, t.dx.back().col(0), check)))
        << ToString(method);
  }
  Simulator sim(scene, TightOptions(Method::kPd));
  const Rollout rollout = sim.Simulate(sim.RestState(), std::vector<StepInput>(2));
  InputDirection bad;
  bad.activation = {VectorXd::Ones(2), VectorXd()};
  ASSERT_THROW_MESSAGE(sim.Tangents(rollout, {bad}), InvalidInputError,
                       "Tangents: direction 0 has an activation with 2 entries, expected 1 (one per muscle)");
}

// The small beam swimming in a current, damped, its lower nodes pressed
// into a penalty floor with friction: every explicit state force.
Scene SwimmingBeamScene() {
  Scene scene = testing::SmallBeamScene(/*tets=*/true);
  Hydrodynamics water;
  water.triangles = BoundaryTriangles(scene.mesh);
  water.thrust = 0.7;
  water.flow_velocity = Vec3(0.05, -0.1, 0.03);
  scene.hydrodynamics = water;
  scene.linear_damping = 0.8;
  PenaltyContact floor;
  floor.offset = 0.001;  // the bottom nodes start 1 mm inside
  floor.stiffness = 300;
  floor.friction = 0.5;
  floor.friction_velocity = 0.05;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) < 1e-9 && scene.mesh.vertices(0, i) > 1e-9) floor.nodes.push_back(i);
  scene.penalty_contacts = {floor};
  return scene;
}

// Each state-force parameter alone as a direction (unit component), then
// the density, x0 and v0 with every state force acting.
std::vector<InputDirection> StateForceDirections(int n) {
  std::vector<InputDirection> dirs(9);
  dirs[0].state_forces.linear_damping = 1;
  dirs[1].state_forces.fluid_density = 1e3;
  dirs[2].state_forces.drag_tangential = 1;
  dirs[3].state_forces.drag_normal = 1;
  dirs[4].state_forces.thrust = 1;
  dirs[5].state_forces.flow_velocity = Vec3(0.1, 0, 0);
  dirs[6].state_forces.flow_velocity = Vec3(0, 0.1, -0.05);
  dirs[7].state_forces.penalty_friction = {1.0};
  InputDirection rho = InputDirection::Density();
  rho.density = 1e3;
  dirs[8] = rho;
  std::mt19937_64 rng(5);
  InputDirection x0, v0;
  x0.x0 = RandomVector(n, &rng, 1e-2);
  v0.v0 = RandomVector(n, &rng, 0.1);
  dirs.push_back(x0);
  dirs.push_back(v0);
  return dirs;
}

// Moves a scene's state-force parameters by eps along a direction's components.
using ForcePerturbation = std::function<void(Scene*, const StateForceGradient&, double)>;
// The state-force part of dL/dtheta . d.
using ForceDot = std::function<double(const StateForceGradient& gradient, const StateForceGradient& direction)>;

// For Newton-Cholesky, PD-LBFGS and semi-implicit Euler (at its own time step
// if > 0): every state's tangent along every direction against central
// differences of rollouts perturbed along it (x0, v0, density, and the
// state-force parameters by `perturb`), and each direction's tangent against
// reverse mode on a random linear loss of every state.
void ExpectStateForceTangentsMatch(const Scene& scene,
                                   const std::function<std::vector<InputDirection>(int)>& directions,
                                   const ForcePerturbation& perturb, const ForceDot& dot, double semi_implicit_step) {
  for (Method method : {Method::kNewtonCholesky, Method::kPdLbfgs, Method::kSemiImplicit}) {
    SCOPED_TRACE(ToString(method));
    SolverOptions options = TightOptions(method);
    if (method == Method::kSemiImplicit && semi_implicit_step > 0) options.time_step = semi_implicit_step;
    Simulator sim(scene, options);
    const int n = sim.num_dofs();
    const State start = MovingStart(sim);
    const int steps = method == Method::kSemiImplicit ? 20 : 4;
    const Rollout rollout = sim.Simulate(start, std::vector<StepInput>(steps));
    const std::vector<InputDirection> dirs = directions(n);
    const TangentRollout t = sim.Tangents(rollout, dirs);
    auto perturbed = [&](const InputDirection& d, double eps) {
      Scene s = scene;
      s.material.density += eps * d.density;
      perturb(&s, d.state_forces, eps);
      Simulator other(s, options);
      State init = start;
      if (d.x0.size()) init.x += eps * d.x0;
      if (d.v0.size()) init.v += eps * d.v0;
      return other.Simulate(init, std::vector<StepInput>(steps));
    };
    // Semi-implicit steps solve nothing: their noise is rounding.
    const double noise = method == Method::kSemiImplicit ? 1e-15 : options.rel_tolerance;
    const double eps = testing::CentralDifferenceStep(noise, 1.0);
    for (size_t p = 0; p < dirs.size(); ++p) {
      const Rollout plus = perturbed(dirs[p], eps);
      const Rollout minus = perturbed(dirs[p], -eps);
      testing::DifferenceOptions check;
      check.noise = noise;
      // The implicit solves converge far below their tolerance (no floor);
      // semi-implicit differences carry the states' rounding over 20 steps,
      // which matters for damping's tangents (1e-5 of the states).
      check.floor = method == Method::kSemiImplicit ? 1e-14 * plus.states.back().x.norm() / eps : 0.0;
      check.rtol = 1e-5;  // the differences' truncation reaches 2e-6 of the tangent
      for (int k = 1; k <= steps; ++k) check.derivative_scale = std::max(check.derivative_scale, t.dx[k].col(p).norm());
      ASSERT_GT(check.derivative_scale, 0.0) << "direction " << p;
      for (int k = 1; k <= steps; ++k)
        EXPECT_TRUE(testing::Passes(
            testing::CompareCentralDifference(plus.states[k].x, minus.states[k].x, eps, t.dx[k].col(p), check)))
            << "direction " << p << " x_" << k;
    }
    std::mt19937_64 rng(3);
    LossGradient loss(steps);
    for (int k = 0; k <= steps; ++k) {
      loss.dx[k] = RandomVector(n, &rng, 1.0);
      loss.dv[k] = RandomVector(n, &rng, 0.01);
    }
    const RolloutGradient g = sim.Backward(rollout, loss);
    for (size_t p = 0; p < dirs.size(); ++p) {
      double forward = 0;
      for (int k = 0; k <= steps; ++k) forward += loss.dx[k].dot(t.dx[k].col(p)) + loss.dv[k].dot(t.dv[k].col(p));
      const InputDirection& d = dirs[p];
      double reverse = g.density * d.density + dot(g.state_forces, d.state_forces);
      if (d.x0.size()) reverse += g.x0.dot(d.x0);
      if (d.v0.size()) reverse += g.v0.dot(d.v0);
      EXPECT_NEAR(forward, reverse, 1e-8 * std::abs(reverse)) << "direction " << p;
    }
  }
}

// Forward mode through damping, drag and thrust, and penalty friction, along
// their parameters and along the states and density they depend on, vs
// central differences of every state and vs reverse mode.
TEST(TangentRolloutTest, StateForceTangentsMatchCentralDifferencesAndReverseMode) {
  ExpectStateForceTangentsMatch(
      SwimmingBeamScene(), StateForceDirections,
      [](Scene* s, const StateForceGradient& d, double eps) {
        *s->linear_damping += eps * d.linear_damping;
        s->hydrodynamics->fluid_density += eps * d.fluid_density;
        s->hydrodynamics->drag_tangential += eps * d.drag_tangential;
        s->hydrodynamics->drag_normal += eps * d.drag_normal;
        s->hydrodynamics->thrust += eps * d.thrust;
        s->hydrodynamics->flow_velocity += eps * d.flow_velocity;
        if (!d.penalty_friction.empty()) s->penalty_contacts[0].friction += eps * d.penalty_friction[0];
      },
      [](const StateForceGradient& g, const StateForceGradient& d) {
        double dot = g.linear_damping * d.linear_damping + g.fluid_density * d.fluid_density +
                     g.drag_tangential * d.drag_tangential + g.drag_normal * d.drag_normal + g.thrust * d.thrust +
                     g.flow_velocity.dot(d.flow_velocity);
        if (!d.penalty_friction.empty()) dot += g.penalty_friction[0] * d.penalty_friction[0];
        return dot;
      },
      /*semi_implicit_step=*/0);
}

// A hexahedral beam in a current of water on one-sided quads: the flow
// (about 0.5 m/s) outruns the beam's own motion, so no face changes side
// within the differences' steps (the force jumps where one does).
Scene QuadSwimmingBeamScene() {
  Scene scene = testing::SmallBeamScene();
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(scene.mesh);
  water.flow_velocity = Vec3(0.3, -0.4, 0.2);
  scene.quad_hydrodynamics = water;
  return scene;
}

// Forward mode through the quad hydrodynamics along its parameters and along
// x0, v0 and the density, vs central differences of every state and vs
// reverse mode (semi-implicit at h = 1e-4 s, where it is stable).
TEST(TangentRolloutTest, QuadHydrodynamicsTangentsMatchCentralDifferencesAndReverseMode) {
  auto directions = [](int n) {
    std::vector<InputDirection> dirs(6);
    dirs[0].state_forces.quad_hydrodynamics.fluid_density = 1e3;
    dirs[1].state_forces.quad_hydrodynamics.flow_velocity = Vec3(0.1, 0.05, -0.1);
    dirs[2].state_forces.quad_hydrodynamics.drag_curve = Eigen::Vector4d(0.1, -0.2, 0.3, 0.5);
    dirs[3].state_forces.quad_hydrodynamics.thrust_curve = Eigen::Vector4d(-0.3, 0.2, 0.4, 1.0);
    std::mt19937_64 rng(7);
    dirs[4].x0 = RandomVector(n, &rng, 1e-3);
    dirs[5].v0 = RandomVector(n, &rng, 0.05);
    InputDirection rho = InputDirection::Density();
    rho.density = 1e3;
    dirs.push_back(rho);
    return dirs;
  };
  ExpectStateForceTangentsMatch(
      QuadSwimmingBeamScene(), directions,
      [](Scene* s, const StateForceGradient& d, double eps) {
        const QuadHydrodynamicsGradient& q = d.quad_hydrodynamics;
        s->quad_hydrodynamics->fluid_density += eps * q.fluid_density;
        s->quad_hydrodynamics->flow_velocity += eps * q.flow_velocity;
        s->quad_hydrodynamics->drag_curve += eps * q.drag_curve;
        s->quad_hydrodynamics->thrust_curve += eps * q.thrust_curve;
      },
      [](const StateForceGradient& g, const StateForceGradient& d) {
        const QuadHydrodynamicsGradient &gq = g.quad_hydrodynamics, &q = d.quad_hydrodynamics;
        return gq.fluid_density * q.fluid_density + gq.flow_velocity.dot(q.flow_velocity) +
               gq.drag_curve.dot(q.drag_curve) + gq.thrust_curve.dot(q.thrust_curve);
      },
      /*semi_implicit_step=*/1e-4);
}

TEST(TangentRolloutTest, RejectsStateForceDirectionsTheSceneDoesNotDeclare) {
  Scene scene = testing::SmallBeamScene();
  scene.linear_damping = 0.5;
  Simulator sim(scene, TightOptions(Method::kNewtonCholesky));
  const Rollout rollout = sim.Simulate(sim.RestState(), std::vector<StepInput>(2));
  InputDirection thrust;
  thrust.state_forces.thrust = 1;
  ASSERT_THROW_MESSAGE(sim.Tangents(rollout, {InputDirection::Density(), thrust}), InvalidInputError,
                       "Tangents: direction 1 has a hydrodynamics component, but the scene declares no hydrodynamics");
  Simulator swim(SwimmingBeamScene(), TightOptions(Method::kNewtonCholesky));
  const Rollout swim_rollout = swim.Simulate(swim.RestState(), std::vector<StepInput>(2));
  InputDirection friction;
  friction.state_forces.penalty_friction = {1.0, 2.0};
  ASSERT_THROW_MESSAGE(swim.Tangents(swim_rollout, {friction}), InvalidInputError,
                       "Tangents: direction 0 has penalty_friction for 2 contacts, expected 0 or 1 (one per penalty "
                       "contact)");
  InputDirection quad;
  quad.state_forces.quad_hydrodynamics.drag_curve(2) = 1;
  ASSERT_THROW_MESSAGE(swim.Tangents(swim_rollout, {quad}), InvalidInputError,
                       "Tangents: direction 0 has a quad_hydrodynamics component, but the scene declares no quad "
                       "hydrodynamics");
  InputDirection nan;
  nan.state_forces.linear_damping = std::nan("");
  ASSERT_THROW_MESSAGE(sim.Tangents(rollout, {nan}), InvalidInputError,
                       "Tangents: direction 0 has a non-finite state-force component");
  Scene dry = testing::SmallBeamScene();
  Simulator dry_sim(dry, TightOptions(Method::kNewtonCholesky));
  const Rollout dry_rollout = dry_sim.Simulate(dry_sim.RestState(), std::vector<StepInput>(2));
  InputDirection damping;
  damping.state_forces.linear_damping = 1;
  ASSERT_THROW_MESSAGE(dry_sim.Tangents(dry_rollout, {damping}), InvalidInputError,
                       "Tangents: direction 0 has a linear_damping component, but the scene declares no linear "
                       "damping");
}

}  // namespace
}  // namespace diffpd
