// A paper row through the rollout core and either optimiser (L-BFGS-B, and
// Ipopt where it is built): the row's rollout function gives the row's own
// loss and gradient, an optimisation lowers the loss within its evaluation
// budget and stops by L-BFGS-B's ftol test, and `diffpd table --optimise`
// reports the optimiser's evaluations and final normalised loss.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "diffpd/error.h"
#include "paper/paper_rows.h"
#include "paper/row_evaluation.h"
#include "paper/row_optimisation.h"
#include "paper/row_rollout_function.h"
#include "tools/table.h"

namespace diffpd::problems {
namespace {

TEST(RowOptimisationTest, TheRowsRolloutFunctionGivesTheRowsLossAndGradient) {
  PaperRow row = MakeBunnyRow(RowSize::kSmall);
  SolverOptions options = row.Options(Method::kPdLbfgs, 1);
  // One adjoint solver for both paths: the automatic choice follows measured
  // times, and two adjoint solvers agree only to their tolerance.
  options.adjoint_solver = AdjointSolver::kDirect;
  row.Prepare(options);
  Simulator sim(row.scene, options);
  const VectorXd x = row.initial();
  const RowEvaluation e = EvaluateRow(row, &sim, x, true);
  RowRolloutFunction f = MakeRowRolloutFunction(row, options);
  VectorXd weights = VectorXd::Zero(f.function->num_rows());
  for (size_t t = 0; t < f.loss_rows.size(); ++t) weights(f.loss_rows[t]) += f.loss_weights[t];
  VectorXd gradient;
  double loss = 0;
  ASSERT_TRUE(f.function->Gradient(x, weights, &gradient, &loss)) << f.function->statistics().last_error;
  EXPECT_NEAR(loss, e.loss, 1e-10 * std::abs(e.loss));
  ASSERT_EQ(gradient.size(), e.gradient.size());
  EXPECT_LE((gradient - e.gradient).norm(), 1e-8 * e.gradient.norm());
  EXPECT_EQ(f.function->lower_bounds(), row.lower());
  EXPECT_EQ(f.function->upper_bounds(), row.upper());
}

std::vector<RowOptimizer> Optimizers() {
#if DIFFPD_TEST_IPOPT
  return {RowOptimizer::kLbfgsb, RowOptimizer::kIpopt};
#else
  return {RowOptimizer::kLbfgsb};
#endif
}

class RowOptimiserTest : public ::testing::TestWithParam<RowOptimizer> {};

TEST_P(RowOptimiserTest, AnOptimisationLowersThePlantLossAndStopsAtItsEvaluationBudget) {
  PaperRow row = MakePlantRow(RowSize::kSmall);
  const SolverOptions options = row.Options(Method::kPdLbfgs, 1);
  row.Prepare(options);
  RowOptimisationOptions o;
  o.optimizer = GetParam();
  o.max_evaluations = 6;
  long reported = 0;
  o.on_evaluation = [&](long k, double loss, double forward_s) {
    EXPECT_GT(k, reported);
    EXPECT_TRUE(std::isfinite(loss));
    EXPECT_GE(forward_s, 0);
    reported = k;
  };
  const RowOptimisationResult r = OptimiseRow(row, options, o);
  EXPECT_EQ(r.optimizer, ToString(GetParam()));
  EXPECT_EQ(r.stopped_by, "evaluation budget") << r.status;
  EXPECT_GE(r.evaluations, 6);
  EXPECT_EQ(reported, r.evaluations);
  EXPECT_GE(r.gradients, 1);
  EXPECT_LT(r.final_loss, 0.75 * r.initial_loss);
  EXPECT_GT(r.forward_s, 0);
  EXPECT_GT(r.backward_s, 0);
  for (int j = 0; j < r.x.size(); ++j) {
    EXPECT_GE(r.x(j), row.lower()(j));
    EXPECT_LE(r.x(j), row.upper()(j));
  }
}

// L-BFGS-B's stopping test (L-BFGS-B's own, and mapped onto Ipopt's
// iterations): the run stops at the first iteration whose relative decrease
// of the loss is at most ftol.
TEST_P(RowOptimiserTest, ItStopsAtTheFirstIterationThatDecreasesTheLossByAtMostFtol) {
  PaperRow row = MakePlantRow(RowSize::kSmall);
  row.budget.ftol = 0.05;
  const SolverOptions options = row.Options(Method::kPdLbfgs, 1);
  row.Prepare(options);
  RowOptimisationOptions o;
  o.optimizer = GetParam();
  o.max_evaluations = 40;
  const RowOptimisationResult r = OptimiseRow(row, options, o);
  ASSERT_EQ(r.stopped_by, "relative decrease") << r.status;
  const std::vector<double>& f = r.loss_history;
  ASSERT_GE(f.size(), 2u);
  const auto small_decrease = [&](size_t k) {
    const double d = f[k - 1] - f[k];
    return d >= 0 && d <= row.budget.ftol * std::max({std::abs(f[k - 1]), std::abs(f[k]), 1.0});
  };
  EXPECT_TRUE(small_decrease(f.size() - 1));
  for (size_t k = 1; k + 1 < f.size(); ++k) EXPECT_FALSE(small_decrease(k)) << "iteration " << k;
}

INSTANTIATE_TEST_SUITE_P(Optimizers, RowOptimiserTest, ::testing::ValuesIn(Optimizers()),
                         [](const ::testing::TestParamInfo<RowOptimizer>& info) {
                           return std::string(ToString(info.param));
                         });

TEST(RowOptimisationTest, OptimizerNamesParseAndAnUnknownOneIsRefused) {
  EXPECT_EQ(ParseRowOptimizer("lbfgsb"), RowOptimizer::kLbfgsb);
  EXPECT_EQ(ParseRowOptimizer("ipopt"), RowOptimizer::kIpopt);
  try {
    ParseRowOptimizer("bfgs");
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "optimizer 'bfgs' is unknown: use lbfgsb or ipopt");
  }
}

TEST(RowOptimisationTest, TheTableReportsTheOptimisersEvaluationsAndFinalNormalisedLoss) {
  TableOptions o;
  o.rows = {"plant"};
  o.methods = {Method::kPdLbfgs, Method::kNewtonCholesky};
  o.threads = 1;
  o.size = RowSize::kSmall;
  o.evaluations = 1;
  o.optimise = true;
  o.optimiser_evaluations = 6;
  const TableResult r = RunTable(o, nullptr, {});
  EXPECT_EQ(r.optimizer, "lbfgsb");  // the default: the paper's optimiser
  const TableRowResult& plant = r.rows[0];
  const TableMethodResult* pd = plant.method("pd-lbfgs");
  ASSERT_TRUE(pd->optimisation);
  EXPECT_EQ(pd->optimisation->optimizer, "lbfgsb");
  EXPECT_GE(pd->optimisation->evaluations, 6);
  ASSERT_TRUE(pd->optimisation->normalised_loss);
  ASSERT_TRUE(pd->normalised_loss);
  EXPECT_LT(*pd->optimisation->normalised_loss, *pd->normalised_loss);
  EXPECT_DOUBLE_EQ(*pd->optimisation->normalised_loss, pd->optimisation->final_loss / *plant.random_loss_mean);
  EXPECT_FALSE(plant.method("newton-cholesky")->optimisation);  // Newton: timed at x_init only
  const TableResult back = TableFromJson(TableToJson(r));
  ASSERT_TRUE(back.rows[0].method("pd-lbfgs")->optimisation);
  EXPECT_EQ(back.rows[0].method("pd-lbfgs")->optimisation->final_loss, pd->optimisation->final_loss);
  EXPECT_EQ(back.rows[0].method("pd-lbfgs")->optimisation->loss_history, pd->optimisation->loss_history);
  EXPECT_EQ(back.rows[0].method("pd-lbfgs")->optimisation->optimizer, "lbfgsb");
  EXPECT_EQ(back.optimizer, "lbfgsb");
#if DIFFPD_TEST_IPOPT
  // A resume that would optimise with the other optimizer is refused.
  o.optimizer = RowOptimizer::kIpopt;
  try {
    RunTable(o, &back, {});
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "resume: the file was optimised with lbfgsb, this run asks for ipopt");
  }
#endif
}

}  // namespace
}  // namespace diffpd::problems
