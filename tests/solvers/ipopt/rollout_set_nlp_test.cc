// The Ipopt TNLP over a rollout set's loss (rollout_set_nlp.h) on the beam
// terms of the rollout-set tests: the gradient matches central differences
// of the objective (summed and least-squares losses); the program has the
// set's variables, bounds and start and no constraints; Ipopt lowers the
// loss within the bounds; a null set is refused.
#include "diffpd/solvers/ipopt/rollout_set_nlp.h"

#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "diffpd/solvers/ipopt/ipopt_solve.h"
#include "solvers/core/rollout_set_terms.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd::testing {
namespace {

using solvers::LocalRolloutSet;
using solvers::RolloutSetNlp;
using solvers::TermObjective;

LocalRolloutSet BeamSet(TermObjective objective) {
  std::vector<solvers::RolloutTerm> terms;
  for (int t = 0; t < 3; ++t) terms.push_back(BeamTerm(t));
  return LocalRolloutSet(std::move(terms), objective);
}

TEST(RolloutSetNlpTest, GradientMatchesCentralDifferencesOfTheObjective) {
  for (TermObjective objective : {TermObjective::kSum, TermObjective::kLeastSquares}) {
    LocalRolloutSet set = BeamSet(objective);
    RolloutSetNlp nlp(&set);
    VectorXd p = set.initial_parameters();
    p(0) *= 1.2;  // E (in 1e5 Pa) away from the terms' own value
    std::vector<double> grad(2);
    ASSERT_TRUE(nlp.eval_grad_f(2, p.data(), true, grad.data())) << nlp.last_error();
    const auto f = [&](const VectorXd& q) {
      double value = 0;
      EXPECT_TRUE(nlp.eval_f(2, q.data(), true, value)) << nlp.last_error();
      return value;
    };
    DifferenceOptions check;
    check.noise = 1e-12;  // the beam's rollouts are solved to 1e-12 (TightOptions)
    check.rtol = 1e-5;
    check.step = 1e-4;  // E is O(1) in its units, nu 0.1 from its pole (0.5)
    EXPECT_TRUE(Passes(CheckGradient(f, p, Eigen::Map<const VectorXd>(grad.data(), 2), check)))
        << (objective == TermObjective::kSum ? "sum" : "least squares");
  }
}

TEST(RolloutSetNlpTest, HasTheSetsVariablesBoundsAndStartAndNoConstraints) {
  LocalRolloutSet set = BeamSet(TermObjective::kLeastSquares);
  RolloutSetNlp nlp(&set);
  Ipopt::Index n = 0, m = -1, nnz_jac = -1, nnz_h = -1;
  Ipopt::TNLP::IndexStyleEnum style;
  ASSERT_TRUE(nlp.get_nlp_info(n, m, nnz_jac, nnz_h, style));
  EXPECT_EQ(n, 2);
  EXPECT_EQ(m, 0);
  EXPECT_EQ(nnz_jac, 0);
  double lower[2], upper[2], x[2];
  ASSERT_TRUE(nlp.get_bounds_info(2, lower, upper, 0, nullptr, nullptr));
  ASSERT_TRUE(nlp.get_starting_point(2, true, x, false, nullptr, nullptr, 0, false, nullptr));
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(lower[i], std::isfinite(set.lower_bounds()(i)) ? set.lower_bounds()(i) : -1e20);
    EXPECT_EQ(upper[i], std::isfinite(set.upper_bounds()(i)) ? set.upper_bounds()(i) : 1e20);
    EXPECT_EQ(x[i], set.initial_parameters()(i));
  }
  EXPECT_THROW_MESSAGE(RolloutSetNlp(nullptr), InvalidInputError, "RolloutSetNlp: the rollout set is null");
}

TEST(RolloutSetNlpTest, IpoptLowersTheSummedLossWithinTheBounds) {
  LocalRolloutSet set = BeamSet(TermObjective::kLeastSquares);
  Ipopt::SmartPtr<RolloutSetNlp> nlp = new RolloutSetNlp(&set);
  solvers::IpoptOptions options;
  options.int_options.push_back({"print_level", 0});
  options.int_options.push_back({"max_iter", 5});
  const solvers::IpoptSummary summary = solvers::SolveRolloutSetWithIpopt(nlp, options);
  EXPECT_LT(summary.objective, summary.initial_objective) << summary.BriefReport();
  EXPECT_EQ(summary.constraint_violation, 0.0);
  EXPECT_GE(summary.iterations, 1);
  EXPECT_EQ(summary.objective_history.size(), static_cast<size_t>(summary.iterations) + 1);
  EXPECT_EQ(summary.objective_history.front(), summary.initial_objective);
  double at_x = 0;
  ASSERT_TRUE(set.Value(summary.x, &at_x));
  EXPECT_EQ(at_x, summary.objective);
  EXPECT_GT(summary.evaluations, 0);
}

}  // namespace
}  // namespace diffpd::testing
