// Speed/accuracy sweeps on a tiny cantilever: errors fall as the tolerance,
// the time step and the mesh are refined; JSON rows and the gnuplot PNG.
// (tradeoff_problems_test sweeps the other problems' own losses.)
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include <nlohmann/json.hpp>

#include "diffpd/error.h"
#include "tools/tradeoff.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

TradeoffOptions Tiny() {
  TradeoffOptions o;
  o.instance.refine = -9;  // 4 x 1 x 1 cells
  o.instance.steps = 3;
  o.threads = 1;
  o.max_iterations = 10000;  // plain PD needs ~2500 iterations per step at 1e-8 here
  o.sweep_tolerance = o.sweep_solver_options = o.sweep_time_step = o.sweep_resolution = false;
  return o;
}

// Rows of one sweep and method, in order.
std::vector<TradeoffRow> Select(const std::vector<TradeoffRow>& rows, const std::string& sweep,
                                const std::string& method) {
  std::vector<TradeoffRow> out;
  for (const auto& r : rows)
    if (r.sweep == sweep && r.method == method) out.push_back(r);
  return out;
}

TEST(TradeoffTest, ErrorsFallAsTheToleranceTightens) {
  TradeoffOptions o = Tiny();
  o.sweep_tolerance = true;
  o.methods = {Method::kPd, Method::kPdLbfgs, Method::kNewtonCholesky};
  o.tolerances = {1e-1, 1e-3, 1e-5, 1e-8};
  const auto rows = RunTradeoff("cantilever", o).rows;
  ASSERT_EQ(rows.size(), 13u);  // the default and 3 x 4
  EXPECT_EQ(rows[0].sweep, "default");
  for (Method m : o.methods) {
    const auto r = Select(rows, "tolerance", ToString(m));
    ASSERT_EQ(r.size(), 4u);
    for (const auto& row : r) ASSERT_TRUE(row.failure.empty()) << row.failure;
    // Endpoints: seven decades of tolerance buy at least three of error
    // (measured: four to six).
    EXPECT_LT(r.back().state_rel_error, 1e-3 * r.front().state_rel_error) << ToString(m);
    EXPECT_LT(r.back().grad_rel_error, 1e-3 * r.front().grad_rel_error) << ToString(m);
    // Monotone within noise in between, and tighter tolerances cost more.
    for (size_t k = 1; k < r.size(); ++k) {
      EXPECT_LT(r[k].state_rel_error, 2 * r[k - 1].state_rel_error) << ToString(m) << " " << r[k].value;
      EXPECT_GE(r[k].iters_per_step, r[k - 1].iters_per_step) << ToString(m) << " " << r[k].value;
    }
    EXPECT_EQ(r.front().parameter, "rel_tolerance");
    EXPECT_EQ(r.front().value, 1e-1);
  }
}

// The rolling sphere screens its contact solves at 0.1 (its own setting): the
// screening sweep's run at 0.1 repeats the default's settings, and counts
// as the default's when the front takes the fastest run of those settings.
TEST(TradeoffTest, AScreeningRunAtTheScenesOwnToleranceHasTheDefaultsSettings) {
  TradeoffOptions o;
  o.instance.steps = 2;
  o.threads = 1;
  o.methods = {Method::kPdLbfgs};
  o.tolerances = {1e-4};
  o.backward_factors = {1};
  o.sweep_tolerance = o.sweep_time_step = o.sweep_resolution = false;
  int screening_runs = 0;
  for (const auto& r : RunTradeoff("rolling-sphere", o).rows) {
    if (r.sweep != "screening") continue;
    ++screening_runs;
    EXPECT_EQ(r.default_settings, r.value == 0.1) << r.value;
  }
  EXPECT_EQ(screening_runs, 3);
}

TEST(TradeoffTest, StateErrorFallsWithTheTimeStepAtFixedDuration) {
  TradeoffOptions o = Tiny();
  o.sweep_time_step = true;
  o.methods = {Method::kNewtonCholesky};
  o.rel_tolerance = 1e-8;
  o.time_step_levels = 3;  // h = 10, 5, 2.5 ms; reference 1.25 ms
  const auto r = Select(RunTradeoff("cantilever", o).rows, "time_step", "newton-cholesky");
  ASSERT_EQ(r.size(), 3u);
  EXPECT_DOUBLE_EQ(r[0].value, 0.01);
  EXPECT_DOUBLE_EQ(r[2].value, 0.0025);
  EXPECT_EQ(r[0].steps, 3);
  EXPECT_EQ(r[2].steps, 12);
  // Implicit Euler is first order; against a reference at h/8 the measured
  // errors fall 0.50 -> 0.34 -> 0.20.
  EXPECT_LT(r[1].state_rel_error, r[0].state_rel_error);
  EXPECT_LT(r[2].state_rel_error, 0.7 * r[0].state_rel_error);
  EXPECT_GT(r[2].state_rel_error, 1e-3);  // discretisation error, not solver error
}

TEST(TradeoffTest, CornerErrorIsSmallOnTheReferenceMeshAndLargerOnACoarserOne) {
  TradeoffOptions o = Tiny();
  o.instance.refine = -6;  // finest mesh 8 x 2 x 2; coarser 4 x 1 x 1
  o.sweep_resolution = true;
  o.methods = {Method::kNewtonCholesky};
  o.resolution_levels = 2;
  const auto r = Select(RunTradeoff("cantilever", o).rows, "resolution", "newton-cholesky");
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0].value, 4);
  EXPECT_EQ(r[1].value, 32);
  EXPECT_EQ(r[0].parameter, "elements");
  // On the reference mesh only the solver tolerance (the default 1e-6) separates them.
  EXPECT_LT(r[1].state_rel_error, 1e-2);
  EXPECT_GT(r[0].state_rel_error, 10 * r[1].state_rel_error);
}

TEST(TradeoffTest, JsonRowsHaveTheDocumentedFields) {
  TradeoffOptions o = Tiny();
  o.sweep_tolerance = true;
  o.methods = {Method::kNewtonCholesky};
  o.tolerances = {1e-2, 1e-6};
  const nlohmann::json all = nlohmann::json::parse(TradeoffToJson(RunTradeoff("cantilever", o).rows).dump());
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all[0].at("sweep"), "default");
  for (size_t k = 1; k < all.size(); ++k) {
    const auto& row = all[k];
    EXPECT_EQ(row.at("sweep"), "tolerance");
    EXPECT_EQ(row.at("method"), "newton-cholesky");
    EXPECT_EQ(row.at("parameter"), "rel_tolerance");
    for (const char* field : {"value", "seconds", "state_rel_error", "loss_rel_error", "grad_rel_error"})
      EXPECT_TRUE(row.at(field).is_number()) << field;
  }
}

TEST(TradeoffOptionsTest, ValidateNamesTheFieldValueAndRange) {
  TradeoffOptions o;
  o.tolerances = {1e-3, 2};
  ASSERT_THROW_MESSAGE(o.Validate(), InvalidInputError, "tolerance = 2 is invalid: must be in (0, 1)");
  o = TradeoffOptions();
  o.time_step_levels = 0;
  EXPECT_THROW(o.Validate(), InvalidInputError);
}

TEST(TradeoffTest, RepeatsKeepTheErrorsAndTheCpuClockCountsCpuSeconds) {
  TradeoffOptions o = Tiny();
  o.sweep_tolerance = true;
  o.methods = {Method::kPdLbfgs};
  o.tolerances = {1e-3};
  const auto once = RunTradeoff("cantilever", o);
  o.repeats = 3;
  o.clock = TradeoffClock::kCpu;
  const auto thrice = RunTradeoff("cantilever", o);
  EXPECT_EQ(thrice.repeats, 3);
  ASSERT_EQ(once.rows.size(), 2u);
  ASSERT_EQ(thrice.rows.size(), 2u);
  for (size_t i = 0; i < once.rows.size(); ++i) {
    const TradeoffRow &a = once.rows[i], &b = thrice.rows[i];
    ASSERT_TRUE(a.ok() && b.ok()) << a.failure << b.failure;
    // One thread: the repeated forward passes are the same computation, and
    // the adjoint agrees (at least to its tolerance).
    EXPECT_EQ(a.state_rel_error, b.state_rel_error);
    EXPECT_EQ(a.iters_per_step, b.iters_per_step);
    EXPECT_NEAR(a.grad_rel_error, b.grad_rel_error, 1e-2 * a.grad_rel_error);
    // Wall clock: the passes' seconds; CPU clock: the evaluation's CPU seconds.
    EXPECT_DOUBLE_EQ(a.seconds, a.forward_s + a.backward_s);
    EXPECT_GT(a.cpu_s, 0);
    EXPECT_EQ(b.seconds, b.cpu_s);
    EXPECT_GT(b.cpu_s, 0);
  }
}

TEST(TradeoffTest, ZeroRepeatsIsRejected) {
  TradeoffOptions o;
  o.repeats = 0;
  ASSERT_THROW_MESSAGE(o.Validate(), InvalidInputError, "repeats = 0 is invalid: must be >= 1");
}

std::vector<TradeoffRow> SyntheticRows() {
  std::vector<TradeoffRow> rows;
  for (const char* sweep : {"tolerance", "time_step", "resolution"})
    for (const char* method : {"pd", "newton-cholesky"})
      for (int k = 1; k <= 3; ++k) {
        TradeoffRow r;
        r.sweep = sweep;
        r.method = method;
        r.seconds = 0.1 * k;
        r.state_rel_error = std::pow(10.0, -2 * k);
        r.grad_rel_error = k == 3 ? 0.0 : std::pow(10.0, -k);  // a zero error is drawn at 1e-17
        rows.push_back(r);
      }
  return rows;
}

TEST(TradeoffPlotTest, WritesAPngWithGnuplot) {
  if (!GnuplotAvailable()) GTEST_SKIP() << "gnuplot is not installed";
  const testing::TemporaryDirectory dir("diffpd-tradeoff-plot");
  const std::string path = dir.File("tradeoff.png");
  WriteTradeoffPlot(SyntheticRows(), path, "test");
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_GT(std::filesystem::file_size(path), 1000u);
}

TEST(TradeoffJsonTest, RowsReadBackAsWritten) {
  std::vector<TradeoffRow> rows = SyntheticRows();
  rows[1].failure = "rollout failed (maximum number of iterations reached)";
  rows[2].setting = "direct";
  rows[2].default_settings = true;
  rows[3].iters_per_step = 4.5;
  rows[3].dofs = 243;
  rows[3].steps = 10;
  const std::vector<TradeoffRow> back = TradeoffRowsFromJson(TradeoffToJson(rows));
  ASSERT_EQ(back.size(), rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(back[i].sweep, rows[i].sweep) << i;
    EXPECT_EQ(back[i].method, rows[i].method) << i;
    EXPECT_EQ(back[i].setting, rows[i].setting) << i;
    EXPECT_EQ(back[i].failure, rows[i].failure) << i;
    EXPECT_EQ(back[i].default_settings, rows[i].default_settings) << i;
    EXPECT_EQ(back[i].dofs, rows[i].dofs) << i;
    EXPECT_EQ(back[i].steps, rows[i].steps) << i;
    if (!rows[i].ok()) continue;  // a failed run's numbers are written as null
    EXPECT_EQ(back[i].seconds, rows[i].seconds) << i;
    EXPECT_EQ(back[i].state_rel_error, rows[i].state_rel_error) << i;
    EXPECT_EQ(back[i].grad_rel_error, rows[i].grad_rel_error) << i;
    EXPECT_EQ(back[i].iters_per_step, rows[i].iters_per_step) << i;
  }
}

TEST(TradeoffJsonTest, AMissingFieldNamesTheRowAndTheField) {
  nlohmann::json rows = TradeoffToJson(SyntheticRows());
  rows[2].erase("grad_rel_error");
  EXPECT_THROW_MESSAGE(TradeoffRowsFromJson(rows), InvalidInputError,
                       "the report's row 2 is invalid: field 'grad_rel_error' is missing or has the wrong type");
  EXPECT_THROW_MESSAGE(TradeoffRowsFromJson(nlohmann::json::object()), InvalidInputError,
                       "the report's rows are invalid: must be a list");
}

TEST(TradeoffPlotTest, MissingGnuplotIsAClearError) {
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  setenv("PATH", "/nonexistent-diffpd-test-dir", 1);
  EXPECT_FALSE(GnuplotAvailable());
  const testing::TemporaryDirectory dir("diffpd-tradeoff-plot");
  EXPECT_THROW_MESSAGE(
      WriteTradeoffPlot(SyntheticRows(), dir.File("unused.png"), "test"), std::runtime_error,
      "--plot needs the gnuplot program, which is not on PATH (Debian: apt-get install gnuplot-nox), or "
      "leave out --plot");
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
  setenv("PATH", path.c_str(), 1);
}

}  // namespace
}  // namespace diffpd::problems
