// The verdict on a derivative from central differences at several steps, on
// synthetic functions with known noise: a correct derivative passes (or, under
// noise too large to resolve it, is unresolved and says the floor), a wrong
// one fails; the chosen step balances truncation and noise.
#include "tools/derivative_verdict.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>
#include <stdexcept>

namespace diffpd::problems {
namespace {

// Central differences of f at x over steps 1e-1, 1e-2, ... (count of them),
// each evaluation carrying uniform noise of amplitude `noise` (declared to
// the judge as noise / e, the bound on the difference's error).
std::vector<FiniteDifference> Differences(const std::function<double(double)>& f, double x, double noise, int count,
                                          std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::vector<FiniteDifference> out;
  double e = 1e-1;
  for (int k = 0; k < count; ++k, e /= 10) {
    const double plus = f(x + e) + noise * unit(rng), minus = f(x - e) + noise * unit(rng);
    out.push_back({e, (plus - minus) / (2 * e), noise / e});
  }
  return out;
}

double F(double x) { return std::exp(x) * std::sin(3 * x); }
double DF(double x) { return std::exp(x) * (std::sin(3 * x) + 3 * std::cos(3 * x)); }

TEST(DerivativeVerdictTest, ACorrectDerivativeWithSmallNoisePassesWithItsMarginStated) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const auto d = Differences(F, 0.4, 1e-13, 6, seed);
    const DerivativeJudgement j = JudgeDerivative(DF(0.4), d, 1e-4);
    EXPECT_EQ(j.verdict, CheckVerdict::kPass) << j.reason;
    EXPECT_LT(j.error, 1e-7);
    EXPECT_GE(j.margin, 100.0);
    EXPECT_EQ(j.margin, 1e-4 / std::max(j.error, j.floor));
    EXPECT_TRUE(j.reason.empty());
    // Truncation ~ e^2 and noise ~ 1e-13 / e balance near e = 1e-4.
    EXPECT_GE(j.step, 1e-5);
    EXPECT_LE(j.step, 1e-3);
  }
}

// A loss that is C1 but not C2 (|x| x, as drag |u| u on a body that starts
// at rest) has central differences that converge as e, not e^2: the floor
// measured from the larger step must cover that, so the correct derivative
// never fails, a wrong one still does, and a smooth loss keeps the
// second-order estimate (its floors are those of r^2 - 1).
TEST(DerivativeVerdictTest, FirstOrderTruncationIsCoveredByTheFloorAndCannotFailACorrectDerivative) {
  auto kinked = [](double x) { return 2 * x + 5 * std::abs(x) * x; };  // at x = 0: fd(e) = 2 + 5 e
  const auto d = Differences(kinked, 0.0, 0.0, 6, 1);
  for (const double tolerance : {1e-4, 1e-5, 1e-6}) {
    const DerivativeJudgement right = JudgeDerivative(2.0, d, tolerance, /*extrapolate=*/false);
    EXPECT_NE(right.verdict, CheckVerdict::kFail) << tolerance << ": " << right.reason;
    EXPECT_GE(right.floor, 0.9 * right.error) << tolerance;
  }
  const DerivativeJudgement wrong = JudgeDerivative(2.0 * (1 + 1e-3), d, 1e-4);
  EXPECT_EQ(wrong.verdict, CheckVerdict::kFail) << wrong.reason;
  // Smooth (truncation ~ e^2, no noise): the floor at the chosen step is the
  // distance to the larger step / 99 or the smaller step's distance / 10.
  auto smooth = [](double x) { return 2 * x + 5 * x * x * x; };  // fd(e) = 2 + 5 e^2
  const auto s = Differences(smooth, 0.0, 0.0, 4, 1);
  const DerivativeJudgement j = JudgeDerivative(2.0, s, 1e-4, /*extrapolate=*/false);
  size_t k = 0;
  while (s[k].step != j.step) ++k;
  ASSERT_GT(k, 0u);
  const double scale = std::max(std::abs(s[k].value), 2.0);
  const double expected =
      std::max(std::abs(s[k - 1].value - s[k].value) / 99, std::abs(s[k + 1].value - s[k].value) / 10);
  EXPECT_NEAR(j.floor, expected / scale, 1e-3 * expected / scale);
}

// Truncation-limited differences (a large e^2 term, noise that rules out the
// smaller steps; shaped like the measured density derivative of the
// calibrate-plant check with semi-implicit Euler) pass by a small margin on
// their own; their Richardson extrapolations confirm the derivative with a
// much larger one. The extrapolation cannot pass a wrong derivative, nor
// replace the differences' own verdict where it is the less certain.
TEST(DerivativeVerdictTest, RichardsonExtrapolationConfirmsATruncationLimitedDerivativeWithALargerMargin) {
  // fd(e) = 3 + 42 e^2 + 3 e^4: 1.4e-5 relative truncation at e = 1e-3; the
  // noise, 7.5e-9 per evaluation, up to 2.5e-5 relative at e = 1e-4.
  auto curved = [](double x) { return 3 * x + 42 * x * x * x + 3 * std::pow(x, 5) + 1; };
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const auto d = Differences(curved, 0.0, 7.5e-9, 5, seed);
    const DerivativeJudgement plain = JudgeDerivative(3.0, d, 1e-4, /*extrapolate=*/false);
    ASSERT_EQ(plain.verdict, CheckVerdict::kPass) << plain.reason;
    EXPECT_LT(plain.margin, 10.0);
    EXPECT_FALSE(plain.extrapolated);
    const DerivativeJudgement x = JudgeDerivative(3.0, d, 1e-4);
    EXPECT_EQ(x.verdict, CheckVerdict::kPass) << x.reason;
    EXPECT_TRUE(x.extrapolated);
    EXPECT_GT(x.margin, 3 * plain.margin);
    EXPECT_GE(x.floor, x.error);  // the extrapolation's own noise and truncation are measured
    // 1e-3 off: the differences resolve it and fail it; the extrapolations
    // do not pass it, so the failure stands.
    const DerivativeJudgement wrong = JudgeDerivative(3.0 * (1 + 1e-3), d, 1e-4);
    EXPECT_EQ(wrong.verdict, CheckVerdict::kFail) << wrong.reason;
    EXPECT_FALSE(wrong.extrapolated);
    // 3e-5 off: the differences pass it at the margin their truncation
    // allows; the extrapolations resolve the offset and give a smaller
    // margin, so the verdict and margin are the differences' own.
    const DerivativeJudgement near = JudgeDerivative(3.0 * (1 + 3e-5), d, 1e-4);
    const DerivativeJudgement near_plain = JudgeDerivative(3.0 * (1 + 3e-5), d, 1e-4, /*extrapolate=*/false);
    EXPECT_FALSE(near.extrapolated);
    EXPECT_EQ(near.verdict, near_plain.verdict);
    EXPECT_EQ(near.margin, near_plain.margin);
  }
  // First-order truncation (|x| x): the extrapolation with the divisor
  // r - 1 confirms the derivative, and still not a wrong one.
  auto kinked = [](double x) { return 2 * x + 5 * std::abs(x) * x + 7 * x * x * x; };
  const auto k = Differences(kinked, 0.0, 1e-16, 6, 1);
  const DerivativeJudgement right = JudgeDerivative(2.0, k, 1e-6);
  EXPECT_EQ(right.verdict, CheckVerdict::kPass) << right.reason;
  EXPECT_TRUE(right.extrapolated);
  EXPECT_NE(JudgeDerivative(2.0, k, 1e-6, /*extrapolate=*/false).verdict, CheckVerdict::kPass);
  EXPECT_NE(JudgeDerivative(2.0 * (1 + 1e-4), k, 1e-6).verdict, CheckVerdict::kPass);
  // Two differences: nothing to extrapolate from.
  EXPECT_FALSE(JudgeDerivative(3.0, Differences(curved, 0.0, 1e-16, 2, 1), 1e-1).extrapolated);
}

TEST(DerivativeVerdictTest, ACorrectDerivativeUnderLargeNoiseIsUnresolvedWithTheFloor) {
  // Noise 1e-6 per evaluation: the best difference is good to ~1e-4 only.
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const auto d = Differences(F, 0.4, 1e-5, 5, seed);
    const DerivativeJudgement j = JudgeDerivative(DF(0.4), d, 1e-5);
    EXPECT_NE(j.verdict, CheckVerdict::kFail) << j.reason;
    if (j.verdict == CheckVerdict::kUnresolved) {
      EXPECT_GT(j.floor, 1e-5);
      EXPECT_NE(j.reason.find("resolve the derivative only to"), std::string::npos) << j.reason;
    }
  }
  // The same noise with a looser tolerance resolves it.
  const DerivativeJudgement loose = JudgeDerivative(DF(0.4), Differences(F, 0.4, 1e-5, 5, 3), 1e-2);
  EXPECT_EQ(loose.verdict, CheckVerdict::kPass) << loose.reason;
  EXPECT_GE(loose.margin, 3.0);
}

TEST(DerivativeVerdictTest, AWrongDerivativeFailsUnderTheSameNoise) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    // 1e-3 relative off: resolved by differences good to 1e-7.
    const DerivativeJudgement small_noise =
        JudgeDerivative(DF(0.4) * (1 + 1e-3), Differences(F, 0.4, 1e-13, 6, seed), 1e-4);
    EXPECT_EQ(small_noise.verdict, CheckVerdict::kFail);
    EXPECT_GT(small_noise.error, 9e-4);
    EXPECT_LT(small_noise.margin, 1.0);
    EXPECT_EQ(small_noise.reason.rfind("differs by ", 0), 0u) << small_noise.reason;
    // 10% off under noise that resolves the derivative to ~1e-4 only.
    const DerivativeJudgement large_noise = JudgeDerivative(DF(0.4) * 1.1, Differences(F, 0.4, 1e-5, 5, seed), 1e-5);
    EXPECT_EQ(large_noise.verdict, CheckVerdict::kFail);
  }
  // A zero derivative where there is one.
  EXPECT_EQ(JudgeDerivative(0.0, Differences(F, 0.4, 1e-13, 6, 1), 1e-4).verdict, CheckVerdict::kFail);
}

TEST(DerivativeVerdictTest, NoiseThatSwampsTheDerivativeIsUnresolvedNotPassedOrFailed) {
  // A derivative of 1e-9 against noise of 1e-6 per evaluation: the differences
  // scatter; the analytic value can neither be confirmed nor refuted.
  const auto flat = [](double x) { return 1e-9 * x; };
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const DerivativeJudgement j = JudgeDerivative(1e-9, Differences(flat, 0.0, 1e-6, 4, seed), 1e-4);
    EXPECT_EQ(j.verdict, CheckVerdict::kUnresolved) << j.reason;
    EXPECT_GT(j.floor, 1.0);
  }
}

TEST(DerivativeVerdictTest, AKinkWithinTheLargerStepsMovesTheChoiceToSmallerOnes) {
  // |x - 0.005| + 2x: derivative 1 at x = 0, seen by steps below 5e-3 only.
  const auto kinked = [](double x) { return std::abs(x - 0.005) + 2 * x; };
  const DerivativeJudgement j = JudgeDerivative(1.0, Differences(kinked, 0.0, 1e-15, 5, 1), 1e-6);
  EXPECT_EQ(j.verdict, CheckVerdict::kPass) << j.reason;
  EXPECT_LE(j.step, 1e-3);
}

// Measured (the one-cell bouncing ball, Newton-Cholesky, E = 1e10 Pa, nu = 0,
// h = 1e-5 s, Poisson's ratio, relative to the derivative): the largest step
// is off by its truncation, -5.5e-4, and the next one's noise (about 5e-4,
// as its neighbours show) happens to land next to it. The truncation is not
// resolved: unresolved, not a failure.
TEST(DerivativeVerdictTest, TruncationHiddenByTheNextStepsNoiseIsNotAFailure) {
  const std::vector<FiniteDifference> d = {{3e-1, 1 - 5.5e-4, 0}, {3e-2, 1 - 4.6e-4, 0}, {1e-2, 1 - 9.6e-4, 0},
                                           {1e-3, 1 + 1.1e-2, 0}, {1e-4, 1 + 0.15, 0},   {1e-5, 1 + 0.31, 0}};
  const DerivativeJudgement j = JudgeDerivative(1.0, d, 1e-4);
  EXPECT_EQ(j.verdict, CheckVerdict::kUnresolved) << j.reason;
  EXPECT_GT(j.floor, j.error / 3);
}

TEST(DerivativeVerdictTest, VerdictsOrderAndNames) {
  EXPECT_EQ(Worse(CheckVerdict::kPass, CheckVerdict::kUnresolved), CheckVerdict::kUnresolved);
  EXPECT_EQ(Worse(CheckVerdict::kFail, CheckVerdict::kUnresolved), CheckVerdict::kFail);
  EXPECT_EQ(Worse(CheckVerdict::kPass, CheckVerdict::kPass), CheckVerdict::kPass);
  EXPECT_STREQ(ToString(CheckVerdict::kPass), "pass");
  EXPECT_STREQ(ToString(CheckVerdict::kFail), "fail");
  EXPECT_STREQ(ToString(CheckVerdict::kUnresolved), "unresolved");
  EXPECT_THROW(JudgeDerivative(1.0, {}, 1e-4), std::invalid_argument);
  EXPECT_THROW(JudgeDerivative(1.0, {{1e-2, 1.0, 0.0}}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace diffpd::problems
