// shark-control: the small instance's training (Adam, the original's
// settings, 10 evaluations) raises the reward by at least half its initial
// magnitude (the initial network drifts the fish backwards; 40 steps of a
// 2 m fish are too short to learn to swim forwards, but not to stop that).
#include <gtest/gtest.h>

#include <cmath>

#include "control/shark_control.h"

namespace diffpd::problems {
namespace {

TEST(SharkControlTest, SmallInstanceTrainingRaisesTheRewardByTheMargin) {
  const SharkControl problem;
  const Swimmer swimmer = problem.MakeSwimmer(true);
  SolverOptions options = problem.BaseOptions(true);
  options.num_threads = 1;
  TrainingSettings settings;
  settings.evaluations = 10;
  const TrainingResult r = TrainSwimmer(swimmer, options, settings);
  ASSERT_EQ(r.history.size(), 11u);
  ASSERT_LT(r.initial_reward(), 0);
  EXPECT_GE(r.final_reward(), r.initial_reward() + 0.5 * std::abs(r.initial_reward()))
      << "reward " << r.initial_reward() << " -> " << r.final_reward();
}

}  // namespace
}  // namespace diffpd::problems
