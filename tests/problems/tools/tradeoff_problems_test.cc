// Trade-off sweeps of problems' own losses and gradients (problem_objective.h)
// on small instances: every run converges, the errors of the final state,
// the loss and the gradient with respect to the problem's own variables do
// not grow as the tolerance tightens (beyond a noise factor of 3), the
// tightest tolerance agrees with the converged reference, and the reference
// comes from its cache the second time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "diffpd/error.h"

#include "tools/problem_objective.h"
#include "tools/tradeoff.h"
#include "tools/tradeoff_front.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

TradeoffOptions Reduced(const std::string& problem, const std::string& cache) {
  TradeoffOptions o;
  o.methods = {Method::kPd, Method::kPdLbfgs, Method::kNewtonCholesky};
  o.tolerances = {1e-2, 1e-4, 1e-6, 1e-8};
  o.threads = 1;
  o.instance.steps = 5;
  if (problem == "cantilever") {
    o.instance.refine = -6;    // 8 x 2 x 2 cells
    o.max_iterations = 10000;  // plain PD needs thousands of iterations per step at 1e-8 on the stiff beam
  }
  o.sweep_solver_options = o.sweep_time_step = o.sweep_resolution = false;
  o.cache_dir = cache;
  return o;
}

class TradeoffProblemsTest : public ::testing::TestWithParam<std::string> {};

TEST_P(TradeoffProblemsTest, ErrorsDoNotGrowAsTheToleranceTightens) {
  const auto names = ObjectiveProblemNames();
  if (std::find(names.begin(), names.end(), GetParam()) == names.end())
    GTEST_SKIP() << GetParam() << " needs an optimiser adapter this build lacks";
  const testing::TemporaryDirectory dir("diffpd-tradeoff-problems");
  const TradeoffOptions o = Reduced(GetParam(), dir.path().string());
  const TradeoffResult result = RunTradeoff(GetParam(), o);
  EXPECT_FALSE(result.reference_cached);
  ASSERT_EQ(result.rows.size(), 1 + o.methods.size() * o.tolerances.size());
  for (const auto& r : result.rows) ASSERT_TRUE(r.ok()) << r.method << " " << r.value << ": " << r.failure;
  for (const auto& v : CheckMonotone(result.rows, 3, 1e-9))
    ADD_FAILURE() << v.method << " " << v.error << " error " << v.tighter_error << " at " << v.tighter_tolerance
                  << " > 3 x " << v.looser_error << " at " << v.looser_tolerance;
  // At 1e-8 every method's gradient is the reference's to 1e-4 (its own
  // truncation error and the adjoint's tolerance).
  for (const auto& r : result.rows) {
    if (r.sweep == "tolerance" && r.value == 1e-8) {
      EXPECT_LT(r.grad_rel_error, 1e-4) << r.method;
      EXPECT_LT(r.loss_rel_error, 1e-4) << r.method;
    }
  }
  // The second sweep reads the reference and measures the same errors for
  // the deterministic direct method.
  TradeoffOptions again = o;
  again.methods = {Method::kNewtonCholesky};
  again.tolerances = {1e-4};
  const TradeoffResult second = RunTradeoff(GetParam(), again);
  EXPECT_TRUE(second.reference_cached);
  ASSERT_EQ(second.rows.size(), 2u);
  for (const auto& r : result.rows) {
    if (r.sweep == "tolerance" && r.method == "newton-cholesky" && r.value == 1e-4) {
      EXPECT_EQ(second.rows[1].grad_rel_error, r.grad_rel_error);
    }
  }
}

// A forward scene (its linear loss over x_0, v_0 and the material) and an
// Ipopt problem with frictional contact (its objective over the gait
// parameters); the others: `diffpd tradeoff --all`.
INSTANTIATE_TEST_SUITE_P(SmallInstances, TradeoffProblemsTest, ::testing::Values("cantilever", "quadruped"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

TEST(ProblemObjectiveTest, EveryListedProblemNamesItsVariablesAndLoss) {
  const auto names = ObjectiveProblemNames();
  EXPECT_NE(std::find(names.begin(), names.end(), "paper-cow"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "starfish-control"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "shark-control"), names.end());
}

// --all sweeps every problem but the closed-loop paper rows, whose small
// instances are starfish-control's and shark-control's.
TEST(ProblemObjectiveTest, AllSweepsEveryProblemButTheClosedLoopPaperRows) {
  const auto names = ObjectiveProblemNames();
  const auto all = AllSweepProblemNames();
  auto has = [](const std::vector<std::string>& v, const std::string& n) {
    return std::find(v.begin(), v.end(), n) != v.end();
  };
  for (const char* row : {"paper-starfish", "paper-shark"}) {
    EXPECT_TRUE(has(names, row)) << row;
    EXPECT_FALSE(has(all, row)) << row;
  }
  EXPECT_EQ(all.size() + 2, names.size());
  for (const auto& n : all) EXPECT_TRUE(has(names, n)) << n;
}

// calibrate-starfish's objective is the default fit's model (E, nu, density,
// slack, lag, length, release lag and the water's three coefficients) on
// half a second of cyclic1 at 2 steps per camera frame.
TEST(ProblemObjectiveTest, CalibrateStarfishMeasuresTheDefaultFitsCostOnHalfASecondOfCyclic1) {
  const auto names = ObjectiveProblemNames();
  if (std::find(names.begin(), names.end(), "calibrate-starfish") == names.end())
    GTEST_SKIP() << "calibrate-starfish needs the Ceres adapter, which this build lacks";
  const ProblemObjective o = MakeProblemObjective("calibrate-starfish", 1);
  EXPECT_EQ(o.variables, "the fitted material, tendon and water values (10)");
  EXPECT_EQ(o.steps, 60);
  EXPECT_FALSE(o.optimiser.empty());
  const ObjectiveMeasurement m = o.measure(o.defaults, {});
  ASSERT_TRUE(m.ok()) << m.failure;
  EXPECT_EQ(m.gradient.size(), 10);
  EXPECT_TRUE(m.gradient.allFinite());
  EXPECT_GT(m.loss, 0);
  EXPECT_GT(m.gradient.norm(), 0);
}

TEST(ProblemObjectiveTest, UnknownProblemListsTheValidOnes) {
  try {
    MakeProblemObjective("no-such-problem", 1);
    FAIL() << "no exception";
  } catch (const InvalidInputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("problem 'no-such-problem' has no trade-off objective: valid problems are cantilever, ", 0), 0u)
        << m;
    EXPECT_NE(m.find("paper-cow"), std::string::npos) << m;
  }
}

// A paper row's front is that of the Table's instance: the original code's
// equal node masses unless lumped ones are asked for, and the choice reaches
// the simulated body (the loss changes with it).
TEST(ProblemObjectiveTest, APaperRowHasTheTablesMassesUnlessAskedForLumpedOnes) {
  const ProblemObjective table = MakeProblemObjective("paper-cantilever", 1);
  ObjectiveInstance lumped_instance;
  lumped_instance.paper_masses = MassLumping::kLumped;
  const ProblemObjective lumped = MakeProblemObjective("paper-cantilever", 1, lumped_instance);
  EXPECT_EQ(table.masses, "equal-nodes");
  EXPECT_EQ(lumped.masses, "lumped");
  const ObjectiveMeasurement a = table.measure(table.defaults, {});
  const ObjectiveMeasurement b = lumped.measure(lumped.defaults, {});
  ASSERT_TRUE(a.ok()) << a.failure;
  ASSERT_TRUE(b.ok()) << b.failure;
  EXPECT_GT(std::abs(a.loss - b.loss), 1e-6 * std::abs(a.loss)) << a.loss << " " << b.loss;
  EXPECT_TRUE(MakeProblemObjective("cantilever", 1).masses.empty());
}

TEST(ProblemObjectiveTest, MassesAreRefusedForAProblemThatIsNotAPaperRow) {
  ObjectiveInstance instance;
  instance.paper_masses = MassLumping::kEqualNodes;
  try {
    MakeProblemObjective("cantilever", 1, instance);
    FAIL() << "no exception";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(),
                 "masses 'equal-nodes' are invalid for cantilever: only the paper's rows (paper-<row>) choose their "
                 "masses");
  }
}

}  // namespace
}  // namespace diffpd::problems
