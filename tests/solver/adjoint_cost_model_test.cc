// AdjointCostModel (SolverOptions::adjoint_solver = kAuto): each solver is
// measured once, then the cheaper runs and the other is measured again
// after max(8, ceil((r - 1) / 0.05)) of the leader's steps (r the ratio of
// their costs), so that rechecks cost at most 5% more; the lead follows the
// costs.
#include "solver/adjoint_cost_model.h"

#include <gtest/gtest.h>

#include <vector>

namespace diffpd::internal {
namespace {

using Solver = AdjointCostModel::Solver;

// Runs `steps` steps with fixed costs per solver and returns the sequence of
// solvers chosen.
std::vector<Solver> RunSteps(AdjointCostModel* model, int steps, double iterative_s, double direct_s) {
  std::vector<Solver> chosen;
  for (int i = 0; i < steps; ++i) {
    const Solver s = model->Next();
    chosen.push_back(s);
    model->Record(s, s == Solver::kIterative ? iterative_s : direct_s);
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

TEST(AdjointCostModelTest, MeasuresTheIterationThenTheFactorisationFirst) {
  AdjointCostModel model;
  EXPECT_EQ(model.Next(), Solver::kIterative);
  model.Record(Solver::kIterative, 1.0);
  EXPECT_TRUE(model.measured(Solver::kIterative));
  EXPECT_FALSE(model.measured(Solver::kDirect));
  EXPECT_EQ(model.Next(), Solver::kDirect);
  model.Record(Solver::kDirect, 2.0);
  EXPECT_EQ(model.Next(), Solver::kIterative);  // the cheaper
}

TEST(AdjointCostModelTest, TheCheaperSolverLeadsAndTheOtherIsRecheckedSoThatRechecksCostAtMostFivePercent) {
  // Close costs (r = 1.25): a recheck after every 8 leader steps.
  AdjointCostModel close;
  std::vector<Solver> chosen = RunSteps(&close, 30, 1.25, 1.0);
  EXPECT_EQ(StepsUsing(chosen, Solver::kIterative), (std::vector<int>{0, 10, 19, 28}));
  EXPECT_EQ(close.RecheckInterval(), 8);
  // r = 3: every ceil(2 / 0.05) = 40 leader steps.
  AdjointCostModel far;
  chosen = RunSteps(&far, 100, 3.0, 1.0);
  EXPECT_EQ(far.RecheckInterval(), 40);
  EXPECT_EQ(StepsUsing(chosen, Solver::kIterative), (std::vector<int>{0, 42, 83}));
  // The extra cost of the rechecks: 2 of 98 steps at 2 more each, under 5%.
  double leader_time = 0, extra = 0;
  for (const Solver s : chosen) (s == Solver::kDirect ? leader_time : extra) += s == Solver::kDirect ? 1.0 : 2.0;
  EXPECT_LE(extra - 2.0, 0.05 * leader_time);  // the first measurement is not a recheck
}

TEST(AdjointCostModelTest, ALeadChangeFollowsTheCosts) {
  AdjointCostModel model;
  RunSteps(&model, 12, 1.25, 1.0);  // direct leads; iteration rechecked at step 10
  // The iteration becomes cheaper: at its next recheck it takes the lead
  // and keeps it; the factorisation is rechecked from then on.
  const std::vector<Solver> chosen = RunSteps(&model, 40, 0.5, 1.0);
  const std::vector<int> iterative = StepsUsing(chosen, Solver::kIterative);
  ASSERT_FALSE(iterative.empty());
  const int first = iterative.front();
  EXPECT_EQ(first, 7);  // the 8th direct step since the last recheck came first
  // r = 2 now: rechecks of the factorisation after ceil(1 / 0.05) = 20 steps.
  EXPECT_EQ(model.RecheckInterval(), 20);
  EXPECT_EQ(StepsUsing(chosen, Solver::kDirect), (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 28}));
}

TEST(AdjointCostModelTest, ConsecutiveMeasurementsAreAveragedAndARecheckRestartsTheEstimate) {
  AdjointCostModel model;
  model.Record(Solver::kIterative, 1.0);
  model.Record(Solver::kIterative, 3.0);
  EXPECT_DOUBLE_EQ(model.estimate(Solver::kIterative), 2.0);
  model.Record(Solver::kDirect, 5.0);
  model.Record(Solver::kIterative, 7.0);  // after another solver: restarts
  EXPECT_DOUBLE_EQ(model.estimate(Solver::kIterative), 7.0);
}

}  // namespace
}  // namespace diffpd::internal
