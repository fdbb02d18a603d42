// AdjointCostModel (SolverOptions::adjoint_solver = kAuto): the first step
// iterates; the direct solve, whose cost is estimated before it runs, is
// never run to be measured unless estimated more than 10% cheaper than the
// iteration; where it is, it leads and the iteration is rechecked after
// max(8, ceil((r - 1) / 0.05)) direct steps (r the ratio of the estimates),
// so that rechecks cost at most 5% more; the lead follows the iteration's
// counted cost.
#include "solver/adjoint_cost_model.h"

#include <gtest/gtest.h>

#include <vector>

namespace diffpd::internal {
namespace {

using Solver = AdjointCostModel::Solver;

// Runs `steps` steps with a fixed direct estimate and a fixed iteration cost
// and returns the sequence of solvers chosen.
std::vector<Solver> RunSteps(AdjointCostModel* model, int steps, double iterative_s, double direct_s) {
  std::vector<Solver> chosen;
  for (int i = 0; i < steps; ++i) {
    model->SetDirectEstimate(direct_s);
    const Solver s = model->Next();
    chosen.push_back(s);
    model->Record(s, s == Solver::kIterative ? iterative_s : 0.0);
  }
  return chosen;
}

// Indices of the steps that used `solver`.
std::vector<int> StepsUsing(const std::vector<Solver>& chosen, Solver solver) {
  std::vector<int> out;
  for (size_t i = 0; i < chosen.size(); ++i)
    if (chosen[i] == solver) out.push_back(static_cast<int>(i));
  return out;
}

TEST(AdjointCostModelTest, TheFirstStepIteratesWhateverTheDirectEstimate) {
  AdjointCostModel model;
  model.SetDirectEstimate(1e-9);
  EXPECT_EQ(model.Next(), Solver::kIterative);
  model.Record(Solver::kIterative, 1.0);
  EXPECT_TRUE(model.measured_iteration());
  EXPECT_EQ(model.Next(), Solver::kDirect);
}

TEST(AdjointCostModelTest, NoDirectStepIsMadeUnlessEstimatedMoreThanTenPercentCheaper) {
  // Direct 1.2x the iteration: 200 steps, not one factorisation (no trial).
  AdjointCostModel model;
  const std::vector<Solver> chosen = RunSteps(&model, 200, 1.0, 1.2);
  EXPECT_TRUE(StepsUsing(chosen, Solver::kDirect).empty());
  // Direct estimated 5% cheaper: within the margin, the iteration keeps
  // every step; 15% cheaper: the factorisation leads from the second step.
  AdjointCostModel close;
  EXPECT_TRUE(StepsUsing(RunSteps(&close, 50, 1.0, 0.95), Solver::kDirect).empty());
  AdjointCostModel cheaper;
  EXPECT_EQ(StepsUsing(RunSteps(&cheaper, 5, 1.0, 0.85), Solver::kDirect), (std::vector<int>{1, 2, 3, 4}));
  // Without a direct estimate (the factor does not fit) the same.
  AdjointCostModel unbounded;
  EXPECT_TRUE(StepsUsing(RunSteps(&unbounded, 20, 1.0, 0.0), Solver::kDirect).empty());
}

TEST(AdjointCostModelTest, TheCheaperDirectSolveLeadsAndTheIterationIsRecheckedSoThatRechecksCostAtMostFivePercent) {
  // Close costs (r = 1.25): a recheck after every 8 direct steps.
  AdjointCostModel close;
  std::vector<Solver> chosen = RunSteps(&close, 30, 1.25, 1.0);
  EXPECT_EQ(StepsUsing(chosen, Solver::kIterative), (std::vector<int>{0, 9, 18, 27}));
  EXPECT_EQ(close.RecheckInterval(), 8);
  // r = 3: every ceil(2 / 0.05) = 40 direct steps.
  AdjointCostModel far;
  chosen = RunSteps(&far, 100, 3.0, 1.0);
  EXPECT_EQ(far.RecheckInterval(), 40);
  EXPECT_EQ(StepsUsing(chosen, Solver::kIterative), (std::vector<int>{0, 41, 82}));
  // The extra cost of the rechecks: 2 of 97 direct steps' time at 2 more
  // each, under 5% (the first step is the first measurement, not a recheck).
  double direct_time = 0, extra = 0;
  for (size_t i = 1; i < chosen.size(); ++i)
    (chosen[i] == Solver::kDirect ? direct_time : extra) += chosen[i] == Solver::kDirect ? 1.0 : 2.0;
  EXPECT_LE(extra, 0.05 * direct_time);
}

TEST(AdjointCostModelTest, ALeadChangeFollowsTheIterationsCountedCost) {
  AdjointCostModel model;
  RunSteps(&model, 12, 1.25, 1.0);  // direct leads; iteration rechecked at step 9
  // The iteration becomes cheaper: at its next recheck it takes the lead and
  // keeps it, with no further direct step.
  const std::vector<Solver> chosen = RunSteps(&model, 40, 0.5, 1.0);
  const std::vector<int> iterative = StepsUsing(chosen, Solver::kIterative);
  ASSERT_FALSE(iterative.empty());
  EXPECT_EQ(iterative.front(), 6);  // after 8 direct steps since the recheck at step 9 (2 of them above)
  EXPECT_EQ(StepsUsing(chosen, Solver::kDirect), (std::vector<int>{0, 1, 2, 3, 4, 5}));
}

TEST(AdjointCostModelTest, ConsecutiveIterationsAreAveragedAndARecheckRestartsTheEstimate) {
  AdjointCostModel model;
  model.Record(Solver::kIterative, 1.0);
  model.Record(Solver::kIterative, 3.0);
  EXPECT_DOUBLE_EQ(model.iteration_estimate(), 2.0);
  model.Record(Solver::kDirect, 0.0);
  model.Record(Solver::kIterative, 7.0);  // after a direct step: restarts
  EXPECT_DOUBLE_EQ(model.iteration_estimate(), 7.0);
}

}  // namespace
}  // namespace diffpd::internal
