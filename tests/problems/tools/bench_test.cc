// The benchmark's rows, errors against the converged reference and JSON, on
// a 4 x 1 x 1 cantilever (3 steps of 10 ms, 60 DoFs).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>

#include "problem_registry.h"
#include "tools/bench.h"
#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

BenchOptions TinyCantilever() {
  BenchOptions o;
  o.refine = -9;  // 4 x 1 x 1 cells
  o.steps = 3;
  o.threads = 1;
  // Plain PD needs ~900 iterations per step at rtol 1e-4 on this twisted
  // beam (the library's limit is 1000): leave it room.
  o.max_iterations = 5000;
  return o;
}

const BenchRow& Row(const BenchResult& r, const std::string& method) {
  for (const auto& row : r.rows)
    if (row.method == method) return row;
  ADD_FAILURE() << "no row for " << method;
  return r.rows.front();
}

TEST(MakeRefinedProblemTest, DoublingsScaleTheCellCountCyclingAxes) {
  const int expected[][2] = {{-9, 4}, {-6, 32}, {-3, 256}, {0, 2048}, {1, 4096}, {2, 8192}, {3, 16384}};
  for (const auto& [doublings, elements] : expected)
    EXPECT_EQ(MakeRefinedProblem("cantilever", doublings)->MakeScene().mesh.num_elements(), elements) << doublings;
  EXPECT_EQ(MakeRefinedProblem("falling-cube", -6)->MakeScene().mesh.num_elements(), 8);
  EXPECT_EQ(MakeRefinedProblem("falling-cube", 3)->MakeScene().mesh.num_elements(), 16 * 16 * 16);
  // The contact scenes' voxel grids: cells whose centre lies inside the ball.
  EXPECT_EQ(MakeRefinedProblem("bouncing-ball", -9)->MakeScene().mesh.num_elements(), 1);
  EXPECT_EQ(MakeRefinedProblem("bouncing-ball", -6)->MakeScene().mesh.num_elements(), 8);
  EXPECT_EQ(MakeRefinedProblem("rolling-sphere", -6)->MakeScene().mesh.num_elements(), 27 - 8);
  EXPECT_EQ(MakeRefinedProblem("rolling-sphere", 0)->MakeScene().mesh.num_elements(), 552);
}

TEST(MakeRefinedProblemTest, GivenCellsAreTheCantileversStartBeforeTheDoublings) {
  EXPECT_EQ(ParseCells("172x43x43"), (std::array<int, 3>{172, 43, 43}));
  EXPECT_EQ(MakeRefinedProblem("cantilever", 0, {5, 3, 2})->MakeScene().mesh.num_vertices(), 6 * 4 * 3);
  EXPECT_EQ(MakeRefinedProblem("cantilever", 2, {5, 3, 2})->MakeScene().mesh.num_elements(), 10 * 6 * 2);
  EXPECT_EQ(MakeRefinedProblem("cantilever", -2, {5, 3, 2})->MakeScene().mesh.num_elements(), 5 * 1 * 1);
  for (const std::string bad : {"12x3", "12x3x", "axbxc", "1x2x3x4", "1,2,3", ""})
    EXPECT_THROW_MESSAGE(ParseCells(bad), InvalidInputError,
                         "cells = '" + bad + "' is invalid: must be three cell counts NXxNYxNZ, e.g. 172x43x43");
  EXPECT_THROW_MESSAGE(MakeRefinedProblem("cantilever", 0, {0, 3, 2}), InvalidInputError,
                       "cells = 0x3x2 is invalid: each count must be in [1, 4096]");
  EXPECT_THROW_MESSAGE(MakeRefinedProblem("falling-cube", 0, {4, 4, 4}), InvalidInputError,
                       "cells are available for cantilever only, not for 'falling-cube'");
}

TEST(MakeRefinedProblemTest, RejectsRefinementsOutOfRangeAndUnknownProblems) {
  std::string problems;
  for (const auto& p : AllProblems()) problems += (problems.empty() ? "" : ", ") + p->name();
  struct Case {
    std::string name;
    int doublings;
    std::string message;
  };
  const Case cases[] = {
      {"cantilever", -10,
       "refinement = -10 is invalid for cantilever: it must be in [-9, 12] (12: 4096 times the cells)"},
      {"cantilever", 100,
       "refinement = 100 is invalid for cantilever: it must be in [-9, 12] (12: 4096 times the cells)"},
      {"falling-cube", 13,
       "refinement = 13 is invalid for falling-cube: it must be in [-9, 12] (12: 4096 times the cells)"},
      {"no-such-problem", 3, "unknown problem 'no-such-problem': valid problems are " + problems},
      {"no-such-problem", 0, "unknown problem 'no-such-problem': valid problems are " + problems},
      {"bouncing-ball", 13,
       "refinement = 13 is invalid for bouncing-ball: it must be in [-9, 12] (12: 4096 times the cells)"},
      {"starfish-control", -6,
       "problem 'starfish-control' cannot be refined: refinement is available for cantilever, falling-cube, "
       "bouncing-ball and rolling-sphere"},
  };
  for (const Case& c : cases) {
    EXPECT_THROW_MESSAGE(MakeRefinedProblem(c.name, c.doublings), InvalidInputError, c.message);
  }
  // Unrefined, any registered problem.
  EXPECT_EQ(MakeRefinedProblem("falling-cube", 0)->name(), "falling-cube");
  EXPECT_EQ(MakeRefinedProblem("bouncing-ball", 0)->name(), "bouncing-ball");
}

TEST(BenchOptionsTest, ValidateNamesTheFieldValueAndRange) {
  BenchOptions o;
  o.rel_tolerance = 0;
  EXPECT_THROW_MESSAGE(o.Validate(), InvalidInputError, "rtol = 0 is invalid: must be in (0, 1)");
  o = BenchOptions();
  o.repeat = 0;
  EXPECT_THROW(o.Validate(), InvalidInputError);
  o = BenchOptions();
  o.methods = {Method::kSemiImplicit};
  EXPECT_THROW(o.Validate(), InvalidInputError);
  o = BenchOptions();
  o.lbfgs_weight_scale = 0;
  EXPECT_THROW_MESSAGE(o.Validate(), InvalidInputError, "lbfgs scale = 0 is invalid: must be in (0, 1]");
  o = BenchOptions();
  o.threads = 99999;
  EXPECT_THROW_MESSAGE(o.Validate(), InvalidInputError,
                       "threads = 99999 is invalid: must be in [0, " + std::to_string(MaxSolverThreads()) +
                           "] (0: OpenMP default; SolverOptions::num_threads)");
}

TEST(RelativeErrorTest, IsTheRelativeTwoNorm) {
  EXPECT_DOUBLE_EQ(RelativeError(Eigen::Vector2d(3, 4), Eigen::Vector2d(0, 0)), 5.0);
  EXPECT_DOUBLE_EQ(RelativeError(Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 2)), 1.0 / std::sqrt(5.0));
}

TEST(BenchTest, RowsCarryEveryMethodAndTheReportedQuantities) {
  BenchOptions o = TinyCantilever();
  const BenchResult r = RunBench("cantilever", o);
  EXPECT_EQ(r.dofs, 60);
  EXPECT_EQ(r.steps, 3);
  ASSERT_EQ(r.rows.size(), 4u);
  EXPECT_EQ(r.rows[0].method, "pd");
  EXPECT_EQ(r.rows[3].method, "newton-cholesky");
  for (const auto& row : r.rows) {
    EXPECT_TRUE(row.failure.empty()) << row.method << ": " << row.failure;
    EXPECT_GT(row.forward_s, 0);
    EXPECT_GT(row.backward_s, 0);
    EXPECT_GE(row.iters_per_step, 1);
    EXPECT_NEAR(row.forward_per_iteration_ms, 1e3 * row.forward_s / (row.iters_per_step * 3), 1e-9);
    ASSERT_TRUE(row.speedup_vs_newton_cholesky.has_value());
    EXPECT_EQ(row.grad_rel_error_by_input.size(), 5u);
  }
  EXPECT_DOUBLE_EQ(*Row(r, "newton-cholesky").speedup_vs_newton_cholesky, 1.0);
  // The adjoint: PD methods iterate, Newton-Cholesky solves directly (Newton-PCG's
  // incomplete Cholesky is exact on this 60-DoF beam: no iteration either).
  EXPECT_EQ(Row(r, "newton-cholesky").backward_iters_per_step, 0.0);
  EXPECT_GE(Row(r, "pd-lbfgs").backward_iters_per_step, 1.0);
  EXPECT_GE(Row(r, "pd").backward_iters_per_step, 1.0);
  // Newton converges quadratically: a few iterations; PD needs hundreds.
  EXPECT_LT(Row(r, "newton-cholesky").iters_per_step, 10);
  EXPECT_GT(Row(r, "pd").iters_per_step, 10 * Row(r, "newton-cholesky").iters_per_step);
  // PD methods factorise A once per fresh simulator, inside the forward time;
  // Newton has no one-off factor (its factorisations are its iterations).
  for (const char* pd : {"pd", "pd-lbfgs"}) {
    EXPECT_GT(Row(r, pd).factorization_s, 0) << pd;
    EXPECT_LT(Row(r, pd).factorization_s, Row(r, pd).forward_s) << pd;
  }
  EXPECT_EQ(Row(r, "newton-cholesky").factorization_s, 0.0);
  EXPECT_EQ(Row(r, "newton-pcg").factorization_s, 0.0);
}

TEST(BenchTest, TightlyConvergedNewtonMatchesTheReference) {
  BenchOptions o = TinyCantilever();
  o.methods = {Method::kNewtonCholesky, Method::kNewtonPcg};
  o.rel_tolerance = 1e-10;
  const BenchResult r = RunBench("cantilever", o);
  // Same solver and tolerance as the reference: the same rollout.
  EXPECT_LT(Row(r, "newton-cholesky").state_rel_error, 1e-8);
  EXPECT_LT(Row(r, "newton-cholesky").grad_rel_error, 1e-8);
  // Another linear solver at the same tolerance (measured 6e-15 and 1.5e-13).
  EXPECT_LT(Row(r, "newton-pcg").state_rel_error, 1e-8);
  EXPECT_LT(Row(r, "newton-pcg").grad_rel_error, 1e-8);
}

TEST(BenchTest, PdErrorAtRtol1e4IsBoundedAndShrinksWithTheTolerance) {
  BenchOptions o = TinyCantilever();
  o.methods = {Method::kPd};
  const double loose = RunBench("cantilever", o).rows[0].state_rel_error;
  // Measured 5.3e-3: the tolerance is on the force residual, and PD leaves
  // its residual in the soft bending modes, where a force error moves the
  // state most; the state's velocity part is x / h, amplifying it by 1/h.
  // The bound allows ~4x for platform differences; far above it would mean
  // PD stops early or the reference is wrong.
  EXPECT_LT(loose, 2e-2);
  EXPECT_GT(loose, 1e-5);  // the solve is genuinely inexact at 1e-4
  o.rel_tolerance = 1e-6;
  o.max_iterations = 10000;
  const double tight = RunBench("cantilever", o).rows[0].state_rel_error;
  // PD converges linearly: the error follows the tolerance (measured 5.3e-5).
  EXPECT_LT(tight, loose / 30);
}

TEST(BenchTest, SpeedupsAreAgainstTheBestNewtonAndThePaperStyleLdltWhichMatchesCholesky) {
  BenchOptions o = TinyCantilever();
  o.methods = {Method::kPdLbfgs, Method::kNewtonPcg, Method::kNewtonCholesky, Method::kNewtonLdlt};
  const BenchResult r = RunBench("cantilever", o);
  ASSERT_EQ(r.rows.size(), 4u);
  const auto total = [&r](const char* method) { return Row(r, method).forward_s + Row(r, method).backward_s; };
  const double best = std::min(total("newton-cholesky"), total("newton-pcg"));
  for (const auto& row : r.rows) {
    ASSERT_TRUE(row.failure.empty()) << row.method << ": " << row.failure;
    const double own = row.forward_s + row.backward_s;
    ASSERT_TRUE(row.speedup_vs_best_newton.has_value()) << row.method;
    ASSERT_TRUE(row.speedup_vs_newton_ldlt.has_value()) << row.method;
    EXPECT_DOUBLE_EQ(*row.speedup_vs_best_newton, best / own) << row.method;
    EXPECT_DOUBLE_EQ(*row.speedup_vs_newton_ldlt, total("newton-ldlt") / own) << row.method;
    // Every backward step is counted once, as iterative or as direct.
    EXPECT_EQ(row.backward_iterative_steps + row.backward_direct_steps, r.steps) << row.method;
  }
  // The paper's Newton is the same Newton with another factorisation: the
  // same iterations and, to rounding, the same state and gradient errors.
  const BenchRow& ldlt = Row(r, "newton-ldlt");
  const BenchRow& cholesky = Row(r, "newton-cholesky");
  EXPECT_EQ(ldlt.backward_direct_steps, r.steps);
  EXPECT_EQ(ldlt.iters_per_step, cholesky.iters_per_step);
  EXPECT_NEAR(ldlt.state_rel_error, cholesky.state_rel_error, 1e-6 * cholesky.state_rel_error);
  EXPECT_NEAR(ldlt.grad_rel_error, cholesky.grad_rel_error, 1e-6 * cholesky.grad_rel_error);
}

TEST(BenchTest, JsonIsAListWithTheRequiredFields) {
  BenchOptions o = TinyCantilever();
  o.methods = {Method::kPdLbfgs, Method::kNewtonCholesky};
  const BenchResult r = RunBench("cantilever", o);
  const nlohmann::json parsed = nlohmann::json::parse(BenchToJson(r, o).dump());
  ASSERT_TRUE(parsed.is_array());
  ASSERT_EQ(parsed.size(), 2u);
  for (const auto& row : parsed) {
    for (const char* field :
         {"forward_s", "backward_s", "iters_per_step", "state_rel_error", "grad_rel_error", "forward_per_iteration_ms",
          "factorization_s", "speedup_vs_newton_cholesky", "backward_iters_per_step", "backward_fallbacks",
          "rounding_floor_steps", "newton_fallback_steps", "speedup_vs_best_newton", "backward_iterative_steps",
          "backward_direct_steps"})
      EXPECT_TRUE(row.at(field).is_number()) << field;
    EXPECT_TRUE(row.at("method").is_string());
    EXPECT_EQ(row.at("status"), "ok");
    EXPECT_EQ(row.at("dofs"), 60);
  }
  EXPECT_EQ(parsed[0].at("method"), "pd-lbfgs");
  EXPECT_DOUBLE_EQ(parsed[0].at("state_rel_error").get<double>(), r.rows[0].state_rel_error);
  // The stacked error is the root of the sum of the parts' squared absolute errors.
  const auto& row = r.rows[0];
  EXPECT_GT(row.position_rel_error, 0.0);
  EXPECT_GT(row.velocity_rel_error, 0.0);
  EXPECT_DOUBLE_EQ(parsed[0].at("position_rel_error").get<double>(), row.position_rel_error);
  EXPECT_DOUBLE_EQ(parsed[0].at("velocity_rel_error").get<double>(), row.velocity_rel_error);
  EXPECT_LE(row.state_rel_error, std::max(row.position_rel_error, row.velocity_rel_error) * (1 + 1e-12));
  EXPECT_GE(row.state_rel_error, std::min(row.position_rel_error, row.velocity_rel_error) * (1 - 1e-12));
}

TEST(BenchTest, AMethodThatFailsIsReportedWithItsSolverError) {
  BenchOptions o = TinyCantilever();
  o.methods = {Method::kPd, Method::kNewtonCholesky};
  o.max_iterations = 20;  // far too few for PD at 1e-4
  const BenchResult r = RunBench("cantilever", o);
  EXPECT_EQ(r.rows[0].failure.rfind("maximum number of iterations reached: pd: the step did not converge in 20", 0), 0u)
      << r.rows[0].failure;
  EXPECT_TRUE(r.rows[1].failure.empty());
  const nlohmann::json rows = BenchToJson(r, o);
  EXPECT_TRUE(rows[0].at("forward_s").is_null());
  EXPECT_EQ(rows[0].at("status").get<std::string>().rfind("failed: maximum number", 0), 0u);
}

TEST(ScalingTest, ElementCountsDoubleAndTimePerIterationIsReported) {
  BenchOptions o = TinyCantilever();
  o.methods = {Method::kPdLbfgs};
  const ScalingResult r = RunScaling("cantilever", o, {1, 2, 4});
  ASSERT_EQ(r.rows.size(), 3u);
  EXPECT_EQ(r.rows[0].elements, 4);
  EXPECT_EQ(r.rows[1].elements, 8);
  EXPECT_EQ(r.rows[2].elements, 16);
  for (const auto& row : r.rows) {
    EXPECT_TRUE(row.failure.empty()) << row.failure;
    EXPECT_GT(row.forward_per_iteration_ms, 0);
    // iteration_ms leaves out the one-off factorisation, which is > 0.
    EXPECT_GT(row.factorization_s, 0);
    EXPECT_GT(row.iteration_ms, 0);
    EXPECT_LT(row.iteration_ms, row.forward_per_iteration_ms);
    EXPECT_NEAR(row.iteration_ms * row.iters_per_step * o.steps, 1e3 * (row.forward_s - row.factorization_s),
                1e-9 * 1e3 * row.forward_s);
    EXPECT_GT(row.peak_rss_mib, 0);
  }
  EXPECT_EQ(r.exponent_per_iteration.count("pd-lbfgs"), 1u);
  EXPECT_EQ(r.exponent_with_factorization.count("pd-lbfgs"), 1u);
  EXPECT_THROW(RunScaling("cantilever", o, {3}), InvalidInputError);
  const nlohmann::json rows = ScalingToJson(r);
  EXPECT_EQ(rows[2].at("dofs"), 3 * 9 * 3 * 2);  // 8 x 2 x 1 cells
}

TEST(ThreadsCompareTest, ReportsOneAndTwoThreadTimes) {
  BenchOptions o = TinyCantilever();
  o.methods = {Method::kNewtonCholesky};
  const auto rows = RunThreadsCompare("cantilever", o, 5);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(rows[0].failure.empty());
  EXPECT_GT(rows[0].step_s_1, 0);
  EXPECT_GT(rows[0].step_s_2, 0);
  EXPECT_GT(rows[0].local_ms_1, 0);
  EXPECT_GT(rows[0].local_speedup(), 0);
  EXPECT_TRUE(ThreadsToJson(rows)[0].at("step_speedup").is_number());
}

}  // namespace
}  // namespace diffpd::problems
