// PD-LBFGS's curvature pairs carried from step to step
// (SolverOptions::lbfgs_carry_pairs): the pairs are used only by a step that
// continues the previous one, every step meets the same convergence test,
// and neither a rollout nor a step that does not continue the previous one
// depends on what the simulator did before. (States are compared to 1e-12,
// not bit for bit: the SVDs are warm-started from earlier evaluations.)
#include <gtest/gtest.h>

#include "diffpd/simulator.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

SolverOptions LbfgsOptions(bool carry) {
  SolverOptions o;
  o.method = Method::kPdLbfgs;
  o.time_step = 0.01;
  o.rel_tolerance = 1e-4;
  o.num_threads = 1;
  o.lbfgs_carry_pairs = carry;
  return o;
}

Scene BeamScene() {
  Scene scene = testing::SmallBeamScene();
  scene.mesh = testing::BoxHexMesh(8, 2, 2, 0.32, 0.04, 0.04);
  scene.dirichlet = DirichletBoundary();
  FixNodes(&scene, testing::NodesAtXMin(scene.mesh));
  return scene;
}

int TotalIterations(const Rollout& r) {
  int total = 0;
  for (const StepReport& rep : r.reports) total += rep.iterations;
  return total;
}

// The same solve up to the round-off of warm-started SVDs.
bool SameSolve(const VectorXd& a, const VectorXd& b, const VectorXd& start) {
  return (a - b).norm() <= 1e-12 * (b - start).norm();
}

TEST(CarriedPairsTest, CarriedPairsChangeThePathNotTheConvergenceTest) {
  const Scene scene = BeamScene();
  Simulator fresh(scene, LbfgsOptions(false));
  Simulator carried(scene, LbfgsOptions(true));
  const State s0 = testing::MovingStart(fresh);
  const Rollout a = fresh.Simulate(s0, std::vector<StepInput>(12));
  const Rollout b = carried.Simulate(s0, std::vector<StepInput>(12));
  EXPECT_EQ(a.reports[0].iterations, b.reports[0].iterations) << "the first step has nothing to carry";
  // Measured here: 354 -> 306 iterations (on other scenes it can cost a few
  // percent; README, "Carried curvature pairs").
  EXPECT_NE(TotalIterations(a), TotalIterations(b)) << "the pairs were not used";
  for (int i = 1; i <= 12; ++i) {
    EXPECT_LE(b.reports[i - 1].final_residual, 1e-4 * b.reports[i - 1].initial_residual + 1e-9);
    // Both meet rtol 1e-4 of the same problem: they agree to its order.
    EXPECT_LT((b.states[i].x - a.states[i].x).norm(), 1e-3 * (a.states[i].x - a.states[i - 1].x).norm())
        << "step " << i;
  }
}

TEST(CarriedPairsTest, ARolloutDoesNotDependOnEarlierCalls) {
  const Scene scene = BeamScene();
  Simulator sim(scene, LbfgsOptions(true));
  const State s0 = testing::MovingStart(sim);
  const Rollout first = sim.Simulate(s0, std::vector<StepInput>(4));
  // Steps continuing the rollout's end leave pairs behind ...
  State s = first.states.back();
  for (int k = 0; k < 3; ++k) s = sim.Step(s, StepInput());
  // ... which the next rollout must not start from, even from that state.
  const Rollout again = sim.Simulate(s0, std::vector<StepInput>(4));
  Simulator other(scene, LbfgsOptions(true));
  const Rollout from_s = other.Simulate(s, std::vector<StepInput>(2));
  const Rollout from_s_again = sim.Simulate(s, std::vector<StepInput>(2));
  for (int i = 1; i <= 4; ++i) {
    EXPECT_EQ(first.reports[i - 1].iterations, again.reports[i - 1].iterations) << "step " << i;
    EXPECT_TRUE(SameSolve(first.states[i].x, again.states[i].x, s0.x)) << "step " << i;
  }
  for (int i = 1; i <= 2; ++i) {
    EXPECT_EQ(from_s.reports[i - 1].iterations, from_s_again.reports[i - 1].iterations) << "step " << i;
    EXPECT_TRUE(SameSolve(from_s.states[i].x, from_s_again.states[i].x, s.x)) << "step " << i;
  }
}

TEST(CarriedPairsTest, OnlyAStepThatContinuesThePreviousOneStartsFromItsPairs) {
  const Scene scene = BeamScene();
  Simulator sim(scene, LbfgsOptions(true));
  const State s0 = testing::MovingStart(sim);
  StepReport r1, r_other, r_continue;
  const State s1 = sim.Step(s0, StepInput(), &r1);
  // A different state (s0 again): solved as by a fresh simulator.
  const State again = sim.Step(s0, StepInput(), &r_other);
  EXPECT_TRUE(SameSolve(again.x, s1.x, s0.x));
  EXPECT_EQ(r_other.iterations, r1.iterations);
  // `again` continues the last step (bit for bit the state it returned): the
  // pairs are used (a different path than a fresh solve of the same step),
  // with the same convergence test. s1 no longer does (it differs from
  // `again` by round-off): solved fresh.
  const State s2 = sim.Step(again, StepInput(), &r_continue);
  Simulator fresh(scene, LbfgsOptions(true));
  StepReport r_fresh;
  const State s2_fresh = fresh.Step(again, StepInput(), &r_fresh);
  EXPECT_FALSE(SameSolve(s2.x, s2_fresh.x, again.x)) << "the pairs were not used";
  EXPECT_LE(r_continue.final_residual, 1e-4 * r_continue.initial_residual + 1e-9);
  EXPECT_LT((s2.x - s2_fresh.x).norm(), 1e-3 * (s2_fresh.x - again.x).norm());
  StepReport r_stale;
  const State from_s1 = sim.Step(s1, StepInput(), &r_stale);
  EXPECT_TRUE(SameSolve(from_s1.x, fresh.Step(s1, StepInput()).x, s1.x));
}

TEST(CarriedPairsTest, AMaterialChangeDropsThePairs) {
  const Scene scene = BeamScene();
  Simulator sim(scene, LbfgsOptions(true));
  const State s0 = testing::MovingStart(sim);
  const State s1 = sim.Step(s0, StepInput());
  MaterialParameters softer = scene.material;
  softer.youngs_modulus *= 0.5;
  sim.SetMaterial(softer);
  Scene soft_scene = scene;
  soft_scene.material = softer;
  Simulator fresh(soft_scene, LbfgsOptions(true));
  StepReport a, b;
  EXPECT_TRUE(SameSolve(sim.Step(s1, StepInput(), &a).x, fresh.Step(s1, StepInput(), &b).x, s1.x));
  EXPECT_EQ(a.iterations, b.iterations);
}

}  // namespace
}  // namespace diffpd
