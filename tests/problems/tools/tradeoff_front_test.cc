// The analysis of a trade-off sweep on made-up rows: the Pareto front of
// seconds against gradient error, the default's slowdown over it, the
// error bounds' fastest settings and loosest tolerances, and the
// monotonicity check with its noise factor; the cached reference's file.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "diffpd/error.h"
#include "tools/reference_cache.h"
#include "tools/tradeoff_front.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

TradeoffRow Row(const std::string& sweep, const std::string& method, double tol, double seconds, double grad_error) {
  TradeoffRow r;
  r.sweep = sweep;
  r.method = method;
  r.parameter = "rel_tolerance";
  r.value = tol;
  r.rel_tolerance = tol;
  r.seconds = seconds;
  r.state_rel_error = r.loss_rel_error = r.grad_rel_error = grad_error;
  return r;
}

// Default pd at 1e-4 (1 s, error 1e-3); pd-lbfgs is faster at every error;
// newton-cholesky slower.
TradeoffResult Made() {
  TradeoffResult r;
  r.problem = "made-up";
  r.default_method = "pd";
  r.default_rel_tolerance = 1e-4;
  r.rows = {Row("default", "pd", 1e-4, 1.0, 1e-3), Row("tolerance", "pd", 1e-2, 0.5, 1e-1),
            Row("tolerance", "pd", 1e-4, 1.0, 1e-3), Row("tolerance", "pd", 1e-6, 2.0, 1e-5),
            Row("tolerance", "pd-lbfgs", 1e-2, 0.3, 5e-2), Row("tolerance", "pd-lbfgs", 1e-4, 0.6, 8e-4),
            Row("tolerance", "pd-lbfgs", 1e-6, 1.2, 1e-5), Row("tolerance", "newton-cholesky", 1e-2, 3.0, 1e-2),
            Row("tolerance", "newton-cholesky", 1e-6, 4.0, 1e-6),
            // Off the problem's settings: never on the front however fast.
            Row("time_step", "pd", 1e-4, 0.01, 1e-9)};
  return r;
}

TEST(TradeoffFrontTest, FrontHoldsTheUndominatedRunsAtTheProblemsSettings) {
  const TradeoffFront f = AnalyseFront(Made());
  // pd-lbfgs 1e-2, 1e-4, 1e-6 and newton-cholesky 1e-6 (the most accurate).
  EXPECT_EQ(f.front, (std::vector<int>{4, 5, 6, 8}));
}

TEST(TradeoffFrontTest, DefaultSlowdownIsOverTheFastestRunAsAccurate) {
  const TradeoffFront f = AnalyseFront(Made());
  EXPECT_DOUBLE_EQ(f.default_slowdown, 1.0 / 0.6);  // pd-lbfgs 1e-4: 8e-4 <= 1e-3 in 0.6 s
  EXPECT_FALSE(f.default_on_front);
  TradeoffResult r = Made();
  r.rows[5].seconds = 0.95;  // within 10%
  r.rows[6].seconds = 0.99;
  EXPECT_TRUE(AnalyseFront(r).default_on_front);
}

TEST(TradeoffFrontTest, DefaultTimeIsTheFastestRunWithItsSettings) {
  TradeoffResult r = Made();
  r.rows[0].default_settings = r.rows[2].default_settings = true;  // pd 1e-4 measured twice
  r.rows[2].seconds = 0.63;
  const TradeoffFront f = AnalyseFront(r);
  EXPECT_DOUBLE_EQ(f.default_seconds, 0.63);
  EXPECT_DOUBLE_EQ(f.default_slowdown, 0.63 / 0.6);
  EXPECT_TRUE(f.default_on_front);
  // A run not marked as repeating the default does not count, however fast.
  r.rows[2].default_settings = false;
  EXPECT_DOUBLE_EQ(AnalyseFront(r).default_seconds, 1.0);
}

TEST(TradeoffFrontTest, ADefaultBetweenTheSweptTolerancesCountsAsItsOwnPoint) {
  TradeoffResult r = Made();
  r.default_rel_tolerance = r.rows[0].value = r.rows[0].rel_tolerance = 1e-3;  // between 1e-2 and 1e-4
  r.rows[0].grad_rel_error = 5e-3;
  const TradeoffFront f = AnalyseFront(r);
  const ErrorBound& b2 = f.bounds[1];  // 1e-2: pd 1e-2 misses it (1e-1), 1e-3 and tighter meet it
  EXPECT_EQ(b2.default_method_tolerance, 1e-3);
  EXPECT_DOUBLE_EQ(b2.loosening, 1.0);
  const ErrorBound& b3 = f.bounds[0];  // 1e-3: the default misses it, pd 1e-4 meets it
  EXPECT_EQ(b3.default_method_tolerance, 1e-4);
  EXPECT_DOUBLE_EQ(b3.loosening, 0.1);
}

TEST(TradeoffFrontTest, BoundsGiveTheFastestSettingAndHowFarTheDefaultMayLoosen) {
  const TradeoffFront f = AnalyseFront(Made());
  ASSERT_EQ(f.bounds.size(), 3u);
  const ErrorBound& b3 = f.bounds[0];
  EXPECT_EQ(b3.bound, 1e-3);
  EXPECT_TRUE(b3.met);
  EXPECT_EQ(b3.method, "pd-lbfgs");
  EXPECT_EQ(b3.rel_tolerance, 1e-4);
  EXPECT_EQ(b3.default_method_tolerance, 1e-4);  // pd's 1e-4 run has exactly 1e-3
  EXPECT_DOUBLE_EQ(b3.loosening, 1.0);
  EXPECT_EQ(b3.pd_lbfgs_tolerance, 1e-4);
  EXPECT_EQ(b3.pd_lbfgs_seconds, 0.6);
  EXPECT_EQ(b3.best_newton_seconds, 4.0);
  const ErrorBound& b1 = f.bounds[2];
  EXPECT_EQ(b1.default_method_tolerance, 1e-2);  // pd at 1e-2: 1e-1 <= 1e-1
  EXPECT_DOUBLE_EQ(b1.loosening, 100.0);
  EXPECT_EQ(b1.method, "pd-lbfgs");
  EXPECT_EQ(b1.seconds, 0.3);
}

TEST(TradeoffFrontTest, AnalysisNeedsTheDefaultFirst) {
  TradeoffResult r = Made();
  r.rows.erase(r.rows.begin());
  EXPECT_THROW_MESSAGE(AnalyseFront(r), InvalidInputError, "AnalyseFront: rows[0] must be the default run");
}

TEST(TradeoffMonotoneTest, ATighterToleranceWithALargerErrorBeyondTheNoiseFactorIsReported) {
  TradeoffResult r = Made();
  EXPECT_TRUE(CheckMonotone(r.rows, 3, 1e-9).empty());
  r.rows[3].grad_rel_error = 2.5e-3;  // pd at 1e-6: 2.5x its 1e-4 error, within a factor 3
  EXPECT_TRUE(CheckMonotone(r.rows, 3, 1e-9).empty());
  const auto v = CheckMonotone(r.rows, 2, 1e-9);
  ASSERT_EQ(v.size(), 1u);
  EXPECT_EQ(v[0].method, "pd");
  EXPECT_EQ(v[0].error, "gradient");
  EXPECT_EQ(v[0].looser_tolerance, 1e-4);
  EXPECT_EQ(v[0].tighter_tolerance, 1e-6);
  EXPECT_EQ(v[0].tighter_error, 2.5e-3);
  // Errors at the floor never count: 1e-12 after 1e-13 is noise.
  r = Made();
  r.rows[2].state_rel_error = 1e-13;
  r.rows[3].state_rel_error = 1e-12;
  EXPECT_TRUE(CheckMonotone(r.rows, 3, 1e-9).empty());
}

TEST(ReferenceCacheTest, SecondLookupReadsTheFileAndAnotherKeyRecomputes) {
  const testing::TemporaryDirectory dir("diffpd-reference-cache");
  int computed = 0;
  auto compute = [&] {
    ++computed;
    ReferenceValues r;
    r.loss = 1.0 / 3;
    r.gradient = VectorXd::LinSpaced(5, 0.1, 0.9);
    r.state = VectorXd::Constant(3, 2.0 / 7);
    r.seconds = 1.5;
    return r;
  };
  bool hit = true;
  const ReferenceValues a = CachedReference(dir.path().string(), "p", "key one", compute, &hit);
  EXPECT_FALSE(hit);
  const ReferenceValues b = CachedReference(dir.path().string(), "p", "key one", compute, &hit);
  EXPECT_TRUE(hit);
  EXPECT_EQ(computed, 1);
  EXPECT_EQ(b.loss, a.loss);  // bit for bit
  EXPECT_EQ(b.gradient, a.gradient);
  EXPECT_EQ(b.state, a.state);
  CachedReference(dir.path().string(), "p", "key two", compute, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(computed, 2);
  // A truncated file is recomputed and rewritten.
  for (const auto& e : std::filesystem::directory_iterator(dir.path())) std::ofstream(e.path()) << "{\"key\":";
  CachedReference(dir.path().string(), "p", "key one", compute, &hit);
  EXPECT_FALSE(hit);
  CachedReference(dir.path().string(), "p", "key one", compute, &hit);
  EXPECT_TRUE(hit);
}

}  // namespace
}  // namespace diffpd::problems
