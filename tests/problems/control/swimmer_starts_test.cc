// Controller training over several initial states (swimmer_starts.h) on a
// short starfish rollout: the starts are the documented states; the summed
// loss's gradient over two starts matches central differences; a set of one
// start trains exactly as the single-rollout training; a multi-start
// training reports per-start rewards that add up to its reward and counts
// every start's steps; bad options are refused with their messages.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "control/starfish_control.h"
#include "control/swimmer_starts.h"
#include "diffpd/error.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

constexpr int kSteps = 10;

Swimmer ShortStarfish() {
  Swimmer s = StarfishControl().MakeSwimmer(true);
  s.steps = kSteps;
  return s;
}

// Deterministic settings: one thread and a fixed adjoint solver.
SolverOptions Options() {
  SolverOptions o = StarfishControl().BaseOptions(true);
  o.num_threads = 1;
  o.adjoint_solver = AdjointSolver::kIterative;
  return o;
}

solvers::LocalRolloutSet Starts(const Swimmer& swimmer, const SolverOptions& options, int count) {
  SwimmerStartsOptions starts;
  starts.count = count;
  std::vector<solvers::RolloutTerm> terms;
  for (int i = 0; i < count; ++i) terms.push_back(SwimmerStartTerm(swimmer, options, 42, i, starts));
  return solvers::LocalRolloutSet(std::move(terms), solvers::TermObjective::kSum);
}

TEST(SwimmerStartsTest, StartZeroIsTheRestStateAndTheOthersMoveLaterallyAsRigidBodies) {
  const Swimmer swimmer = ShortStarfish();
  SwimmerStartsOptions starts;
  starts.count = 3;
  const State rest = MakeSwimmerFunction(swimmer, Options(), 42)->base().initial;
  const State s0 = SwimmerStartState(swimmer, 0, starts);
  EXPECT_EQ(s0.x, rest.x);
  EXPECT_EQ(s0.v, rest.v);
  const State s1 = SwimmerStartState(swimmer, 1, starts), s2 = SwimmerStartState(swimmer, 2, starts);
  EXPECT_EQ(s1.x, rest.x);
  for (int node = 0; node < swimmer.scene.mesh.num_vertices(); ++node) {
    EXPECT_EQ(s1.v.segment<3>(3 * node), Vec3(0.05, 0, 0));
    EXPECT_NEAR((s2.v.segment<3>(3 * node) - Vec3(-0.05, 0, 0)).norm(), 0.0, 1e-15);
  }
}

TEST(SwimmerStartsTest, RefusesBadStartsWithTheirMessages) {
  const Swimmer swimmer = ShortStarfish();
  SwimmerStartsOptions starts;
  starts.count = 0;
  EXPECT_THROW_MESSAGE(SwimmerStartState(swimmer, 0, starts), InvalidInputError, "starts = 0 is invalid: must be >= 1");
  starts.count = 4;
  starts.speed = -1;
  EXPECT_THROW_MESSAGE(SwimmerStartState(swimmer, 0, starts), InvalidInputError,
                       "start speed = -1 is invalid: must be finite and >= 0");
  starts.speed = 0.05;
  EXPECT_THROW_MESSAGE(SwimmerStartState(swimmer, 4, starts), InvalidInputError, "start 4 is out of range [0, 4)");
  solvers::LocalRolloutSet set = Starts(swimmer, Options(), 1);
  TrainingSettings settings;
  settings.evaluations = 0;
  EXPECT_THROW_MESSAGE(TrainOverStarts(&set, kSteps, settings), InvalidInputError,
                       "evaluations = 0 is invalid: must be >= 1");
}

// The gradient of L = L_0 + L_1 (the rest start and a pushed one) along a
// random direction of the 20k weights, against central differences of L at
// tight step tolerances.
TEST(SwimmerStartsTest, SummedLossGradientMatchesCentralDifferences) {
  const Swimmer swimmer = ShortStarfish();
  SolverOptions options = Options();
  options.rel_tolerance = 1e-11;
  options.abs_tolerance = 1e-12;
  options.backward_rel_tolerance = 1e-11;
  solvers::LocalRolloutSet set = Starts(swimmer, options, 2);
  const VectorXd p = set.initial_parameters();
  VectorXd g;
  double value = 0;
  ASSERT_TRUE(set.Gradient(p, &g, &value)) << set.last_error();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  VectorXd d(p.size());
  for (Eigen::Index i = 0; i < d.size(); ++i) d(i) = normal(rng);
  d /= d.norm();
  const auto loss = [&](const VectorXd& q) {
    double l = 0;
    EXPECT_TRUE(set.Value(q, &l)) << set.last_error();
    return l;
  };
  testing::DifferenceOptions check;
  check.noise = 1e-10;
  check.rtol = 1e-5;
  check.input_scale = 0.1;  // a weight of a 64-wide layer: about 1 / sqrt(64)
  EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(loss, p, d, g.dot(d), check)));
}

TEST(SwimmerStartsTest, OneStartTrainsExactlyAsTheSingleRolloutTraining) {
  const Swimmer swimmer = ShortStarfish();
  TrainingSettings settings;
  settings.evaluations = 2;
  const TrainingResult single = TrainSwimmer(swimmer, Options(), settings);
  solvers::LocalRolloutSet set = Starts(swimmer, Options(), 1);
  const MultiStartTraining multi = TrainOverStarts(&set, kSteps, settings);
  EXPECT_EQ(multi.final_parameters, single.final_parameters);
  ASSERT_EQ(multi.history.size(), single.history.size());
  for (size_t e = 0; e < single.history.size(); ++e) EXPECT_EQ(multi.history[e].reward, single.history[e].reward);
}

TEST(SwimmerStartsTest, MultiStartTrainingCountsEveryStartAndItsRewardsAddUp) {
  const Swimmer swimmer = ShortStarfish();
  for (ControlOptimizer optimizer : {ControlOptimizer::kAdam, ControlOptimizer::kLbfgs, ControlOptimizer::kIpopt}) {
    if (!ControlOptimizerAvailable(optimizer)) continue;
    solvers::LocalRolloutSet set = Starts(swimmer, Options(), 2);
    TrainingSettings settings;
    settings.evaluations = 2;
    settings.optimizer = optimizer;
    const MultiStartTraining r = TrainOverStarts(&set, kSteps, settings);
    EXPECT_EQ(r.starts, 2);
    ASSERT_GE(r.history.size(), 2u);
    ASSERT_LE(r.history.size(), 3u);
    for (size_t e = 0; e < r.history.size(); ++e) EXPECT_EQ(r.history[e].simulated_steps, long(e) * 2 * kSteps);
    ASSERT_EQ(r.initial_start_rewards.size(), 2u);
    ASSERT_EQ(r.final_start_rewards.size(), 2u);
    EXPECT_DOUBLE_EQ(r.initial_start_rewards[0] + r.initial_start_rewards[1], r.initial_reward());
    EXPECT_EQ(r.final_start_rewards[0] + r.final_start_rewards[1], r.final_reward());
    // The pushed start differs from the rest start.
    EXPECT_NE(r.initial_start_rewards[0], r.initial_start_rewards[1]);
    EXPECT_GT((r.final_parameters - r.initial_parameters).norm(), 0.0) << ToString(optimizer);
  }
}

}  // namespace
}  // namespace diffpd::problems
