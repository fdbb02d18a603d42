// Tests of the control signals (control_signal.h): values, Jacobians against
// central differences, and argument checks.
#include "diffpd/solvers/core/control_signal.h"

#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

// Jacobian of a signal by central differences.
MatrixXd NumericJacobian(const ControlSignal& s, const VectorXd& c) {
  MatrixXd jac(s.num_steps(), c.size());
  const double eps = 1e-6;
  for (int j = 0; j < c.size(); ++j) {
    VectorXd plus = c, minus = c, vp, vm;
    plus(j) += eps;
    minus(j) -= eps;
    s.Evaluate(plus, &vp, nullptr);
    s.Evaluate(minus, &vm, nullptr);
    jac.col(j) = (vp - vm) / (2 * eps);
  }
  return jac;
}

TEST(ControlSignalTest, PiecewiseLinearInterpolatesKnotsPlacedUniformly) {
  PiecewiseLinearSignal s(5, 3);  // knots at steps 0, 2, 4
  VectorXd v;
  s.Evaluate(Eigen::Vector3d(1.0, 3.0, -1.0), &v, nullptr);
  EXPECT_EQ(v, (VectorXd(5) << 1.0, 2.0, 3.0, 1.0, -1.0).finished());
  EXPECT_EQ(s.FirstStep(0), 0);
  EXPECT_EQ(s.FirstStep(1), 1);
  EXPECT_EQ(s.FirstStep(2), 3);
  EXPECT_TRUE(s.is_linear());
  s.Evaluate(s.ConstantCoefficients(0.7), &v, nullptr);
  EXPECT_TRUE(v.isApproxToConstant(0.7, 1e-15));
}

TEST(ControlSignalTest, FourierSeriesHasTheStatedBasis) {
  const double h = 0.01, period = 0.08;
  FourierSignal s(10, h, period, 2);
  ASSERT_EQ(s.num_coefficients(), 5);
  VectorXd c(5);
  c << 0.5, 0.1, -0.2, 0.3, 0.05;
  VectorXd v;
  MatrixXd jac;
  s.Evaluate(c, &v, &jac);
  for (int k = 0; k < 10; ++k) {
    const double w = 2 * M_PI * k * h / period;
    const double expected =
        0.5 + 0.1 * std::sin(w) - 0.2 * std::cos(w) + 0.3 * std::sin(2 * w) + 0.05 * std::cos(2 * w);
    EXPECT_NEAR(v(k), expected, 1e-15);
  }
  EXPECT_EQ(jac, s.basis());
  s.Evaluate(s.ConstantCoefficients(1.0), &v, nullptr);
  EXPECT_TRUE(v.isApproxToConstant(1.0, 1e-15));
}

TEST(ControlSignalTest, JacobiansMatchCentralDifferences) {
  const SinusoidSignal sinusoid(12, 0.01, 0.05);
  const FourierSignal fourier(12, 0.01, 0.05, 1);
  const PiecewiseLinearSignal pwl(12, 4);
  const PerStepSignal per_step(12);
  const std::vector<const ControlSignal*> signals = {&sinusoid, &fourier, &pwl, &per_step};
  for (const ControlSignal* s : signals) {
    VectorXd c(s->num_coefficients());
    for (int j = 0; j < c.size(); ++j) c(j) = 0.3 + 0.1 * std::sin(1.7 * j);
    MatrixXd jac;
    s->Evaluate(c, nullptr, &jac);
    EXPECT_LE((jac - NumericJacobian(*s, c)).cwiseAbs().maxCoeff(), 1e-9);
  }
  EXPECT_FALSE(sinusoid.is_linear());
  VectorXd v;
  sinusoid.Evaluate(Eigen::Vector3d(0.8, 0.1, 0.3), &v, nullptr);
  EXPECT_NEAR(v(3), 0.8 + 0.1 * std::sin(2 * M_PI * 0.03 / 0.05 + 0.3), 1e-15);
}

TEST(ControlSignalTest, BadArgumentsAreRefusedWithMessages) {
  try {
    PiecewiseLinearSignal(5, 6);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "knots = 6 is invalid: must be in [2, num_steps = 5]");
  }
  try {
    FourierSignal(5, 0.01, 0.0, 1);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "period = 0 is invalid: must be finite and > 0 (s)");
  }
  try {
    PerStepSignal(0);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "num_steps = 0 is invalid: a control signal needs at least 1 step(s)");
  }
  try {
    VectorXd v;
    PerStepSignal(3).Evaluate(VectorXd::Zero(2), &v, nullptr);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "control signal coefficients have 2 entries, expected 3");
  }
}

}  // namespace
}  // namespace diffpd::solvers
