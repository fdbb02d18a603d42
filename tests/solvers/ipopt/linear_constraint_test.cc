// Tests of the linear constraints of the Ipopt adapter (linear_constraint.h):
// signal range rows and their validation messages.
#include "diffpd/solvers/ipopt/linear_constraint.h"

#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

TEST(LinearConstraintTest, SignalRangeRowsBoundEveryStepOnceEvenForAPeriodicSignal) {
  // Period 4 steps over 12 steps: only 4 distinct rows.
  const FourierSignal s(12, 0.01, 0.04, 1);
  const std::vector<LinearConstraint> rows = SignalRangeConstraints(s, 10, 0.5, 1.5, "a");
  ASSERT_EQ(rows.size(), 4u);
  for (const LinearConstraint& r : rows) {
    EXPECT_EQ(r.lower, 0.5);
    EXPECT_EQ(r.upper, 1.5);
    EXPECT_EQ(r.columns.front(), 10);
    EXPECT_NO_THROW(r.Validate(13));
  }
  // Every step's value is one of the rows' values.
  const VectorXd c = Eigen::Vector3d(1.0, 0.2, -0.3);
  VectorXd v;
  s.Evaluate(c, &v, nullptr);
  for (int k = 0; k < 12; ++k) {
    bool found = false;
    for (const LinearConstraint& r : rows) {
      double value = 0;
      for (size_t j = 0; j < r.columns.size(); ++j) value += r.coefficients[j] * c(r.columns[j] - 10);
      found = found || std::abs(value - v(k)) < 1e-12;
    }
    EXPECT_TRUE(found) << "step " << k;
  }
  EXPECT_THROW(SignalRangeConstraints(SinusoidSignal(4, 0.01, 0.04), 0, 0, 1), InvalidInputError);
}

TEST(LinearConstraintTest, ValidateNamesTheProblem) {
  LinearConstraint c;
  c.name = "sum";
  c.columns = {0, 3};
  c.coefficients = {1.0, 1.0};
  try {
    c.Validate(3);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "linear constraint 'sum': column 3 is out of range [0, 3)");
  }
  c.columns = {1, 1};
  try {
    c.Validate(3);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "linear constraint 'sum': column 1 repeats");
  }
  c.columns = {0, 1};
  c.lower = 2;
  c.upper = 1;
  try {
    c.Validate(3);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "linear constraint 'sum': bounds [2, 1] are invalid: need lower <= upper, no NaN");
  }
}

}  // namespace
}  // namespace diffpd::solvers
