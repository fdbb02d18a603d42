// The central-difference policy: the step rule, exact derivatives pass with
// their margin stated, wrong ones fail and say so, the noise floor follows
// the declared noise level, and explicit tolerances are honoured.
#include "util/central_difference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace diffpd::testing {
namespace {

// f(x) = (sin x0 x1, x0^2 + exp(x2)) and its Jacobian.
VectorXd F(const VectorXd& x) { return Eigen::Vector2d(std::sin(x(0) * x(1)), x(0) * x(0) + std::exp(x(2))); }
MatrixXd J(const VectorXd& x) {
  MatrixXd j(2, 3);
  const double c = std::cos(x(0) * x(1));
  j << c * x(1), c * x(0), 0, 2 * x(0), 0, std::exp(x(2));
  return j;
}

TEST(CentralDifferenceTest, StepIsTheCubeRootOfTheNoiseTimesTheInputScale) {
  EXPECT_NEAR(CentralDifferenceStep(1e-12, 1.0), 1e-4, 1e-18);
  EXPECT_NEAR(CentralDifferenceStep(1e-15, 0.1), 1e-6, 1e-20);
  EXPECT_NEAR(CentralDifferenceStep(1e-15, 0.1, 4.0), 2.5e-7, 1e-20);  // per unit of |d|_inf
  EXPECT_THROW(CentralDifferenceStep(0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(CentralDifferenceStep(1e-15, 1.0, 0.0), std::invalid_argument);
}

TEST(CentralDifferenceTest, ExactDerivativesPassWithTheirNumbersStated) {
  const VectorXd x = Eigen::Vector3d(0.7, -1.3, 0.4), d = Eigen::Vector3d(0.2, 1.0, -0.5);
  const DifferenceCheck along = CheckDirectionalDerivative(F, x, d, J(x) * d);
  EXPECT_TRUE(Passes(along));
  EXPECT_NEAR(along.step, std::cbrt(1e-15) * 1.3 / 1.0, 1e-18);
  EXPECT_LT(along.error, 1e-9 * along.analytic);
  EXPECT_GT(along.margin(), 100.0);
  EXPECT_FALSE(along.marginal());
  EXPECT_LT(along.truncation, 1e-8);  // measured
  // The verdict of the differences at 2h, h and h/2: resolved and agreeing.
  EXPECT_EQ(along.verdict, "pass");
  EXPECT_GT(along.verdict_margin, 100.0);
  EXPECT_LT(along.measured_floor, along.tolerance);
  const DifferenceCheck jacobian = CheckJacobian(F, x, J(x));
  EXPECT_TRUE(Passes(jacobian));
  const auto g = [](const VectorXd& y) { return y(0) * y(0) * y(1); };
  EXPECT_TRUE(Passes(CheckGradient(g, x, Eigen::Vector3d(2 * x(0) * x(1), x(0) * x(0), 0.0))));
  EXPECT_TRUE(Passes(CheckDirectionalDerivative(g, x, d, 2 * x(0) * x(1) * d(0) + x(0) * x(0) * d(1))));
}

TEST(CentralDifferenceTest, AWrongDerivativeFailsAndSaysSo) {
  const VectorXd x = Eigen::Vector3d(0.7, -1.3, 0.4), d = Eigen::Vector3d(0.2, 1.0, -0.5);
  MatrixXd wrong = J(x);
  wrong(1, 2) *= 1 + 1e-5;  // one entry off by 1e-5 relative
  const DifferenceCheck c = CheckJacobian(F, x, wrong);
  EXPECT_FALSE(c.passed());
  EXPECT_LT(c.margin(), 1.0);
  EXPECT_FALSE(Passes(c));
  EXPECT_EQ(c.Describe().rfind("central difference FAILS (margin ", 0), 0u) << c.Describe();
  EXPECT_EQ(c.verdict, "fail");  // resolved: the measured floor is far below the error
  EXPECT_LT(c.verdict_margin, 1.0);
  EXPECT_FALSE(CheckDirectionalDerivative(F, x, d, wrong * d).passed());
  // A zero derivative where there is one: the tolerance is relative to |an|
  // = 0 and the noise floor, so it fails.
  EXPECT_FALSE(CheckDirectionalDerivative(F, x, d, VectorXd::Zero(2)).passed());
}

// f with noise of relative size eta: the noise floor eta |f| / h bounds the
// difference's error, and a derivative below it cannot be resolved; the
// check says so instead of failing on noise.
TEST(CentralDifferenceTest, NoiseFloorFollowsTheDeclaredNoiseLevel) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1, 1);
  const double eta = 1e-10;
  const auto noisy = [&](const VectorXd& y) { return 100.0 + 1e-3 * y(0) + 100.0 * eta * unit(rng); };
  DifferenceOptions options;
  options.noise = eta;
  options.estimate_truncation = false;
  const VectorXd x = VectorXd::Constant(1, 1.0), d = VectorXd::Constant(1, 1.0);
  const DifferenceCheck c = CheckDirectionalDerivative(noisy, x, d, 1e-3, options);
  EXPECT_NEAR(c.step, std::cbrt(eta), 1e-15);
  EXPECT_NEAR(c.noise_floor, eta * 100.0 / c.step, 1e-3 * c.noise_floor);
  EXPECT_GT(c.noise_floor, options.rtol * 1e-3);  // 2e-5 > 1e-9: noise-limited
  EXPECT_TRUE(c.passed());
  EXPECT_TRUE(c.marginal());
  EXPECT_NE(c.Describe().find("the noise floor sets the tolerance"), std::string::npos) << c.Describe();
  // With the declared noise too low (rounding), the same noise fails the check.
  options.noise = 1e-15;
  options.step = c.step;
  EXPECT_FALSE(CheckDirectionalDerivative(noisy, x, d, 1e-3, options).passed());
}

TEST(CentralDifferenceTest, ExplicitScaleFloorAndStepAreHonoured) {
  DifferenceOptions options;
  options.rtol = 1e-6;
  options.derivative_scale = 10.0;
  options.floor = 0.0;
  const DifferenceCheck c = CompareCentralDifference(Eigen::Vector2d(1.0, 2.0), Eigen::Vector2d(0.0, 0.0), 0.5,
                                                     Eigen::Vector2d(1.0, 2.0 + 6e-6), options);
  EXPECT_EQ(c.step, 0.5);
  EXPECT_NEAR(c.error, 6e-6, 1e-15);
  EXPECT_DOUBLE_EQ(c.tolerance, 1e-5);  // rtol x the given scale, not |an|
  EXPECT_TRUE(c.passed());
  EXPECT_TRUE(c.marginal());  // margin 1.7
  EXPECT_TRUE(std::isnan(c.truncation));
  options.derivative_scale = 0;
  EXPECT_FALSE(CompareCentralDifference(Eigen::Vector2d(1.0, 2.0), Eigen::Vector2d(0.0, 0.0), 0.5,
                                        Eigen::Vector2d(1.0, 2.0 + 5e-6), options)
                   .passed());
  options.floor = 1e-5;
  EXPECT_TRUE(CompareCentralDifference(3.0, 1.0, 0.5, 2.0 + 9e-6, options).passed());
  EXPECT_FALSE(CompareCentralDifference(3.0, 1.0, 0.5, 2.0 + 2e-5, options).passed());
}

// The truncation estimate flags a kink within the step.
TEST(CentralDifferenceTest, TruncationEstimateFlagsAKinkWithinTheStep) {
  const auto kinked = [](const VectorXd& y) { return std::abs(y(0) - 1e-7); };
  DifferenceOptions options;
  options.input_scale = 1.0;
  const DifferenceCheck c = CheckDirectionalDerivative(kinked, VectorXd::Zero(1), VectorXd::Ones(1), -1.0, options);
  EXPECT_FALSE(c.passed());
  EXPECT_GT(c.truncation, c.tolerance);
  EXPECT_NE(c.Describe().find("f is not smooth within 2h"), std::string::npos) << c.Describe();
}

}  // namespace
}  // namespace diffpd::testing
