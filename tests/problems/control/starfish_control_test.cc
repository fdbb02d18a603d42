// starfish-control: the small instance's training (10 evaluations with
// Adam, the original's settings, Ceres' L-BFGS and Ipopt) raises the reward
// by at least 2 (the reward starts near 0: the initial network barely
// swims) within the budget; `diffpd run
// starfish-control --small` writes the learning curve, the final
// controller's rollout and the summary; bad training settings are refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "control/starfish_control.h"
#include "diffpd/error.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

SolverOptions SmallOptions() {
  SolverOptions o = StarfishControl().BaseOptions(true);
  o.num_threads = 1;
  return o;
}

class StarfishTrainingTest : public ::testing::TestWithParam<ControlOptimizer> {};

// Each optimiser, 10 evaluations of the small instance: the budget holds
// (one row per rollout, at most 10, and the final controller's), the reward
// rises by the margin, and the final rollout is the final controller's.
TEST_P(StarfishTrainingTest, SmallInstanceTrainingRaisesTheRewardByTheMarginWithinTheBudget) {
  if (!ControlOptimizerAvailable(GetParam())) GTEST_SKIP() << "the optimiser's adapter is not built";
  const Swimmer swimmer = StarfishControl().MakeSwimmer(true);
  TrainingSettings settings;
  settings.evaluations = 10;
  settings.optimizer = GetParam();
  const TrainingResult r = TrainSwimmer(swimmer, SmallOptions(), settings);
  EXPECT_EQ(r.optimizer, ToString(GetParam()));
  ASSERT_LE(r.history.size(), 11u);
  ASSERT_GE(r.history.size(), 2u);
  EXPECT_LE(r.history.back().simulated_steps, 400);
  for (size_t e = 0; e + 1 < r.history.size(); ++e) EXPECT_EQ(r.history[e].simulated_steps, 40 * long(e));
  if (GetParam() == ControlOptimizer::kAdam) {
    EXPECT_EQ(r.history.size(), 11u);
    EXPECT_EQ(r.history.back().simulated_steps, 400);
  }
  EXPECT_EQ(r.parameters, 64 * 244 + 64 * 65 + 4 * 65);
  EXPECT_GE(r.final_reward(), r.initial_reward() + 2.0)
      << "reward " << r.initial_reward() << " -> " << r.final_reward();
  // The final rollout is the final controller's, with its reward.
  SwimLoss loss = swimmer.loss;
  EXPECT_DOUBLE_EQ(-loss.Evaluate(r.final_rollout, nullptr), r.final_reward());
  EXPECT_TRUE(r.final_rollout.closed_loop());
  EXPECT_GT((r.final_parameters - r.initial_parameters).norm(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Optimizers, StarfishTrainingTest,
                         ::testing::Values(ControlOptimizer::kAdam, ControlOptimizer::kLbfgs, ControlOptimizer::kIpopt),
                         [](const ::testing::TestParamInfo<ControlOptimizer>& info) { return ToString(info.param); });

TEST(StarfishControlTest, RunWritesTheLearningCurveTheRolloutAndTheSummary) {
  const testing::TemporaryDirectory temp("diffpd-starfish-control");
  CommandArgs args;
  args.problem = "starfish-control";
  args.small = true;
  args.method = Method::kPdLbfgs;
  args.threads = 1;
  args.evaluations = 2;
  args.compare_newton = false;
  args.json = true;  // the table goes to stderr
  args.out_dir = temp.path().string();
  StarfishControl problem;
  const int code = problem.Run(args);
  EXPECT_TRUE(code == 0 || code == 5);
  const std::filesystem::path dir = temp.path();
  EXPECT_TRUE(std::filesystem::exists(dir / "learning_curve.dat"));
  EXPECT_TRUE(std::filesystem::exists(dir / "reference_0.dat"));  // the original DiffPD curve
  EXPECT_TRUE(std::filesystem::exists(dir / "frames" / "starfish-control.pvd"));
  EXPECT_TRUE(std::filesystem::exists(dir / "frames" / "starfish-control_0040.vtu"));
  std::ifstream in(dir / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(in);
  EXPECT_EQ(summary["problem"], "starfish-control");
  EXPECT_EQ(summary["evaluations"], 2);
  EXPECT_EQ(summary["learning_curve"].size(), 3u);
  EXPECT_EQ(code == 0, summary["final_reward"].get<double>() > summary["initial_reward"].get<double>());
}

TEST(StarfishControlTest, RefusesBadTrainingSettings) {
  const Swimmer swimmer = StarfishControl().MakeSwimmer(true);
  TrainingSettings settings;
  settings.evaluations = 0;
  EXPECT_THROW_MESSAGE(TrainSwimmer(swimmer, SmallOptions(), settings), InvalidInputError,
                       "evaluations = 0 is invalid: must be >= 1");
  settings.evaluations = 1;
  settings.adam.beta2 = -0.1;
  EXPECT_THROW_MESSAGE(TrainSwimmer(swimmer, SmallOptions(), settings), InvalidInputError,
                       "adam: beta2 = -0.1 is invalid: must be in [0, 1)");
  CommandArgs args;
  args.small = true;
  args.steps = 10;
  EXPECT_THROW_MESSAGE(StarfishControl().Run(args), InvalidInputError,
                       "--steps and --dt are fixed by the control problem 'starfish-control'; use --small for the "
                       "reduced instance");
  args.steps = -1;
  args.optimizer = "sgd";
  EXPECT_THROW_MESSAGE(StarfishControl().Run(args), InvalidInputError,
                       "optimizer 'sgd' is unknown: valid optimizers are adam, lbfgs, ipopt");
}

}  // namespace
}  // namespace diffpd::problems
