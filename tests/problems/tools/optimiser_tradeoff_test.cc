// The optimiser-level trade-off (optimiser_tradeoff.h) on the small
// quadruped (Ipopt, 126 DoFs): each run's final point is re-evaluated with
// converged settings, so a run at a near-converged tolerance reports the
// loss the re-evaluation finds, the default's tolerance joins the sweep,
// every run shares the same converged start,
// the best run's shortfall is 0 and the others' are >= 0; bad requests get
// exact messages.
#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"
#include "tools/optimiser_tradeoff.h"
#include "tools/problem_objective.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

TEST(OptimiserTradeoffTest, ConvergedReevaluationMatchesATightRunAndShortfallsAreRelativeToTheBest) {
  const ProblemObjective objective = MakeProblemObjective("quadruped", 1);
  ASSERT_TRUE(static_cast<bool>(objective.optimise));
  OptimiserTradeoffOptions options;
  options.max_iterations = 3;
  ASSERT_EQ(objective.defaults.rel_tolerance, 1e-4);
  const OptimiserTradeoff t = RunOptimiserTradeoff(objective, {1e-8, 1e-2}, options, nullptr);
  ASSERT_EQ(t.rows.size(), 3u);  // the default's 1e-4 joins, loosest first
  EXPECT_EQ(t.rows[0].rel_tolerance, 1e-2);
  EXPECT_EQ(t.rows[1].rel_tolerance, 1e-4);
  EXPECT_EQ(t.rows[2].rel_tolerance, 1e-8);
  for (const auto& r : t.rows) {
    ASSERT_TRUE(r.outcome.ok()) << r.outcome.failure;
    EXPECT_GT(r.outcome.evaluations, 0);
    EXPECT_GT(r.outcome.wall_s, 0);
    EXPECT_EQ(r.outcome.initial_loss, t.rows[0].outcome.initial_loss);  // one converged start for all
    EXPECT_GE(r.shortfall, 0);
  }
  // At rel_tolerance 1e-8 the optimiser's own loss is the converged one.
  const OptimiserOutcome& tight = t.rows[2].outcome;
  EXPECT_NEAR(tight.reported_loss, tight.final_loss, 1e-6 * std::abs(tight.final_loss));
  int best = 0;
  for (const auto& r : t.rows) best += r.shortfall == 0;
  EXPECT_GE(best, 1);
  // The JSON report reads back to the same numbers.
  const OptimiserTradeoff back = OptimiserTradeoffFromJson(OptimiserTradeoffJson(t));
  ASSERT_EQ(back.rows.size(), t.rows.size());
  EXPECT_EQ(back.problem, t.problem);
  EXPECT_EQ(back.default_rel_tolerance, t.default_rel_tolerance);
  for (size_t i = 0; i < t.rows.size(); ++i) {
    EXPECT_EQ(back.rows[i].outcome.final_loss, t.rows[i].outcome.final_loss);
    EXPECT_EQ(back.rows[i].outcome.evaluations, t.rows[i].outcome.evaluations);
    EXPECT_EQ(back.rows[i].shortfall, t.rows[i].shortfall);
  }
}

TEST(OptimiserTradeoffTest, RejectsForwardScenesAndBadTolerancesWithExactMessages) {
  const ProblemObjective forward = MakeProblemObjective("falling-cube", 1);
  EXPECT_FALSE(static_cast<bool>(forward.optimise));
  EXPECT_THROW_MESSAGE(RunOptimiserTradeoff(forward, {1e-4}, {}, nullptr), InvalidInputError,
                       "problem 'falling-cube' has no optimiser of its own (a forward scene): the optimiser "
                       "trade-off needs an optimisation, calibration or control problem");
  const ProblemObjective quadruped = MakeProblemObjective("quadruped", 1);
  EXPECT_THROW_MESSAGE(RunOptimiserTradeoff(quadruped, {}, {}, nullptr), InvalidInputError,
                       "tolerances is empty: give at least one relative tolerance");
  EXPECT_THROW_MESSAGE(RunOptimiserTradeoff(quadruped, {1e-4, 1.5}, {}, nullptr), InvalidInputError,
                       "tolerance = 1.5 is invalid: must be in (0, 1)");
  EXPECT_THROW_MESSAGE(OptimiserTradeoffFromJson(nlohmann::json{{"problem", "cow"}}), InvalidInputError,
                       "optimiser trade-off report: [json.exception.out_of_range.403] key 'optimiser' not found");
}

}  // namespace
}  // namespace diffpd::problems
