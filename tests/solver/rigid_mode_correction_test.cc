// RigidModeCorrection (solver/rigid_mode_correction.h) and
// SolverOptions::rigid_mode_correction.
//
// Properties: the modes are infinitesimal rigid motions (every pair of free
// nodes keeps its distance to first order), unit columns, zero at fixed DoFs;
// the correction Z E^+ Z^T inverts H exactly on the coarse space (H Z c maps
// to Z c); with H negative along a mode the correction stays positive
// semi-definite; the products H Z from the energy's frame indifference (plus
// the cut elements' Hessians, grad E taken from the step objective's
// gradient) equal the exact step Hessian's, with fixed nodes, a muscle and
// penalty contact declared; on a spinning free body PD-LBFGS's forward and
// the PD backward need markedly fewer iterations with it, and the states and
// gradients agree with the uncorrected solves within their tolerances;
// clamped bodies are solved without it, bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "diffpd/simulator.h"
#include "solver/rigid_mode_correction.h"
#include "solver/simulator_impl.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

using internal::RigidModeCorrection;

VectorXd SomePositions(int nodes) {
  std::mt19937_64 rng(3);
  return testing::RandomVector(3 * nodes, &rng, 0.2);
}

TEST(RigidModeCorrectionTest, ModesAreUnitRigidMotionsZeroAtFixedDofs) {
  const int nodes = 9;
  const VectorXd x = SomePositions(nodes);
  std::vector<char> fixed(3 * nodes, 0);
  fixed[3 * 4 + 0] = fixed[3 * 4 + 1] = fixed[3 * 4 + 2] = 1;  // node 4 pinned
  const RigidModeCorrection rigid(x, fixed);
  const MatrixXd& z = rigid.modes();
  ASSERT_EQ(z.rows(), 3 * nodes);
  ASSERT_EQ(z.cols(), RigidModeCorrection::kModes);
  for (int k = 0; k < z.cols(); ++k) {
    EXPECT_NEAR(z.col(k).norm(), 1.0, 1e-14) << "mode " << k;
    EXPECT_EQ(z.col(k).segment<3>(3 * 4).norm(), 0.0) << "mode " << k;
    for (int i = 0; i < nodes; ++i) {
      if (i == 4) continue;
      for (int j = i + 1; j < nodes; ++j) {
        if (j == 4) continue;
        const Vec3 dx = x.segment<3>(3 * i) - x.segment<3>(3 * j);
        const Vec3 dz = z.col(k).segment<3>(3 * i) - z.col(k).segment<3>(3 * j);
        EXPECT_NEAR(dx.dot(dz), 0.0, 1e-14) << "mode " << k << " nodes " << i << ", " << j;
      }
    }
  }
  // Translations and rotations are independent: Z has full column rank.
  Eigen::JacobiSVD<MatrixXd> svd(z);
  EXPECT_GT(svd.singularValues().minCoeff(), 0.1);
}

TEST(RigidModeCorrectionTest, InvertsTheHessianOnTheCoarseSpace) {
  const int nodes = 7;
  const VectorXd x = SomePositions(nodes);
  const MatrixXd r = MatrixXd::Random(3 * nodes, 3 * nodes);
  const MatrixXd h = r * r.transpose() + MatrixXd::Identity(3 * nodes, 3 * nodes);
  RigidModeCorrection rigid(x, std::vector<char>(3 * nodes, 0));
  rigid.SetHessianProducts(h * rigid.modes());
  Eigen::Matrix<double, RigidModeCorrection::kModes, 1> c;
  c << 1, -2, 0.5, 3, -1, 2;
  const VectorXd coarse = rigid.modes() * c;
  VectorXd out = VectorXd::Zero(3 * nodes);
  rigid.Add(VectorXd(h * coarse), &out);
  EXPECT_LT((out - coarse).norm(), 1e-10 * coarse.norm());
  // The matrix form agrees column by column.
  MatrixXd outs = MatrixXd::Zero(3 * nodes, 2);
  MatrixXd ins(3 * nodes, 2);
  ins.col(0) = h * coarse;
  ins.col(1) = VectorXd::Random(3 * nodes);
  rigid.Add(ins, &outs);
  VectorXd second = VectorXd::Zero(3 * nodes);
  rigid.Add(VectorXd(ins.col(1)), &second);
  EXPECT_LT((outs.col(0) - coarse).norm(), 1e-10 * coarse.norm());
  EXPECT_LT((outs.col(1) - second).norm(), 1e-12 * second.norm());
}

TEST(RigidModeCorrectionTest, DropsModesWhereTheHessianIsNotPositive) {
  const int nodes = 6;
  const VectorXd x = SomePositions(nodes);
  RigidModeCorrection rigid(x, std::vector<char>(3 * nodes, 0));
  // H = I - 3 z0 z0^T: negative along the first mode, positive elsewhere.
  const VectorXd z0 = rigid.modes().col(0);
  const MatrixXd h = MatrixXd::Identity(3 * nodes, 3 * nodes) - 3 * z0 * z0.transpose();
  rigid.SetHessianProducts(h * rigid.modes());
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const VectorXd r = testing::RandomVector(3 * nodes, &rng, 1.0);
    VectorXd out = VectorXd::Zero(3 * nodes);
    rigid.Add(r, &out);
    EXPECT_GE(r.dot(out), -1e-12 * r.squaredNorm()) << "trial " << trial;
  }
  VectorXd along = VectorXd::Zero(3 * nodes);
  rigid.Add(z0, &along);
  EXPECT_LT(along.dot(z0), 1e-12);  // the indefinite direction gets no correction
}

// The clamped test beam (fixed DoFs cut the modes) with a muscle and a
// penalty floor under its nodes (not frame indifferent), deformed.
TEST(RigidModeCorrectionTest, FrameIndifferenceProductsEqualTheExactHessianProducts) {
  for (const bool tets : {false, true}) {
    Scene scene = testing::SmallBeamScene(tets);
    Muscle muscle;
    for (int e = 0; e < scene.mesh.num_elements(); e += 2) muscle.elements.push_back(e);
    muscle.fibers = {Vec3(1, 0, 0.3)};
    muscle.stiffness = 2e5;
    scene.muscles = {muscle};
    PenaltyContact floor;
    floor.offset = 0.01;  // above the lower nodes: they are pushed
    floor.stiffness = 3e4;
    for (int i = 0; i < scene.mesh.num_vertices(); ++i) floor.nodes.push_back(i);
    scene.penalty_contacts = {floor};
    SolverOptions options;
    options.method = Method::kPdLbfgs;
    options.num_threads = 1;
    internal::SimulatorImpl sim(scene, options);
    const State start = testing::MovingStart(Simulator(scene, options));
    VectorXd x = start.x;
    for (int i = 0; i < x.size() / 3; ++i) x(3 * i + 1) += 0.02 * x(3 * i + 2) - 0.1 * x(3 * i) * x(3 * i);
    ASSERT_GT(std::count(sim.fixed.begin(), sim.fixed.end(), 1), 0);
    const RigidModeCorrection rigid(x, sim.fixed);
    const VectorXd inertia = sim.Mass() / (options.time_step * options.time_step);
    VectorXd elastic_gradient;
    sim.elastic.EnergyAndGradient(x, sim.lame(), &elastic_gradient, 1);
    // PD-LBFGS takes grad E from the step objective's gradient: the same on
    // the free DoFs.
    internal::StepObjective objective(sim, start.x + options.time_step * start.v, sim.ExplicitForce(StepInput()));
    VectorXd grad;
    objective.Evaluate(x, &grad);
    VectorXd free_elastic = elastic_gradient;
    sim.ZeroFixed(&free_elastic);
    EXPECT_LT((objective.ElasticGradient(x, grad) - free_elastic).norm(), 1e-10 * free_elastic.norm());
    const MatrixXd h = internal::RigidModeHessianProducts(sim, rigid, x, objective.ElasticGradient(x, grad), inertia);
    internal::StepLinearization exact(sim, x);
    for (int k = 0; k < RigidModeCorrection::kModes; ++k) {
      const VectorXd reference = exact.Apply(rigid.modes().col(k));
      EXPECT_LT((h.col(k) - reference).norm(), 1e-9 * reference.norm()) << (tets ? "tets" : "hexes") << ", mode " << k;
    }
  }
}

// A free hex block without gravity or fixed nodes: its rigid motion is what
// A^-1 misrepresents.
Scene FreeBlockScene() {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(4, 3, 3, 0.12, 0.09, 0.09);
  scene.material.youngs_modulus = 1e6;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  return scene;
}

// The rest state with a slight bend, a spin and a drift.
State SpinningStart(const Simulator& sim) {
  State s = sim.RestState();
  for (int i = 0; i < s.x.size() / 3; ++i) s.x(3 * i + 2) += 0.05 * s.x(3 * i) * s.x(3 * i);
  const Vec3 omega(4.0, -10.0, 16.0);  // rad/s
  const Vec3 centre(0.06, 0.045, 0.045);
  for (int i = 0; i < s.x.size() / 3; ++i)
    s.v.segment<3>(3 * i) += omega.cross(Vec3(s.x.segment<3>(3 * i)) - centre) + Vec3(0.1, 0, 0);
  return s;
}

SolverOptions LbfgsOptions(bool rigid) {
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.time_step = 0.005;
  options.rel_tolerance = 1e-10;
  options.abs_tolerance = 1e-12;
  options.backward_rel_tolerance = 1e-9;
  // The iterative adjoint (not chosen per step by estimated cost) is what the
  // correction preconditions; its iteration counts are compared.
  options.adjoint_solver = AdjointSolver::kIterative;
  options.num_threads = 1;
  options.rigid_mode_correction = rigid;
  return options;
}

struct SpinRun {
  Rollout rollout;
  RolloutGradient gradient;
  int forward_iterations = 0;
};

SpinRun Simulate(const SolverOptions& options) {
  Simulator sim(FreeBlockScene(), options);
  const int steps = 6;
  SpinRun run;
  run.rollout = sim.Simulate(SpinningStart(sim), std::vector<StepInput>(steps));
  for (const StepReport& r : run.rollout.reports) run.forward_iterations += r.iterations;
  LossGradient loss(steps);
  std::mt19937_64 rng(7);
  loss.dx[steps] = testing::RandomVector(sim.num_dofs(), &rng, 1.0);
  loss.dv[steps] = testing::RandomVector(sim.num_dofs(), &rng, 0.1);
  run.gradient = sim.Backward(run.rollout, loss);
  return run;
}

TEST(RigidModeCorrectionTest, SpinningFreeBodyConvergesInFewerIterationsToTheSameResult) {
  const SpinRun plain = Simulate(LbfgsOptions(false)), corrected = Simulate(LbfgsOptions(true));
  // Measured (6 steps): forward 288 -> 197 iterations, backward 272 -> 199;
  // a correction that did nothing would leave them equal.
  EXPECT_LT(corrected.forward_iterations, 0.8 * plain.forward_iterations)
      << corrected.forward_iterations << " vs " << plain.forward_iterations;
  EXPECT_LT(corrected.gradient.report.linear_iterations, 0.8 * plain.gradient.report.linear_iterations)
      << corrected.gradient.report.linear_iterations << " vs " << plain.gradient.report.linear_iterations;
  EXPECT_EQ(corrected.gradient.report.fallbacks, 0);
  const VectorXd& xa = plain.rollout.states.back().x;
  const VectorXd& xb = corrected.rollout.states.back().x;
  const double travel = (xa - plain.rollout.states.front().x).norm();
  EXPECT_LT((xa - xb).norm(), 1e-7 * travel);
  EXPECT_LT((plain.gradient.x0 - corrected.gradient.x0).norm(), 1e-6 * plain.gradient.x0.norm());
  EXPECT_LT((plain.gradient.v0 - corrected.gradient.v0).norm(), 1e-6 * plain.gradient.v0.norm());
  // The modulus gradient is a sum with cancellation: at these tolerances
  // each run's is within ~1e-6 of the converged value (measured: plain
  // 3.7e-7, corrected 8.3e-7 relative to Newton-Cholesky at 1e-12), so each
  // is checked against that reference rather than against the other.
  SolverOptions converged = LbfgsOptions(false);
  converged.method = Method::kNewtonCholesky;
  converged.rel_tolerance = converged.backward_rel_tolerance = 1e-12;
  converged.abs_tolerance = 1e-14;
  const double reference = Simulate(converged).gradient.youngs_modulus;
  for (const SpinRun* run : {&plain, &corrected})
    EXPECT_NEAR(run->gradient.youngs_modulus, reference, 2e-6 * std::abs(reference))
        << (run == &plain ? "without" : "with") << " the correction";
}

// A clamped body's cut rigid modes are not soft: the option leaves it alone
// (the same iterates, bit for bit).
TEST(RigidModeCorrectionTest, ClampedBodiesAreSolvedWithoutIt) {
  const Scene scene = testing::SmallBeamScene();
  std::vector<Rollout> rollouts;
  std::vector<RolloutGradient> gradients;
  for (const bool rigid : {false, true}) {
    SolverOptions options = LbfgsOptions(rigid);
    Simulator sim(scene, options);
    rollouts.push_back(sim.Simulate(testing::MovingStart(sim), std::vector<StepInput>(3)));
    LossGradient loss(3);
    loss.dx[3] = VectorXd::Ones(sim.num_dofs());
    gradients.push_back(sim.Backward(rollouts.back(), loss));
  }
  EXPECT_EQ(rollouts[0].states.back().x, rollouts[1].states.back().x);
  EXPECT_EQ(gradients[0].x0, gradients[1].x0);
  EXPECT_EQ(gradients[0].report.linear_iterations, gradients[1].report.linear_iterations);
}

}  // namespace
}  // namespace diffpd
