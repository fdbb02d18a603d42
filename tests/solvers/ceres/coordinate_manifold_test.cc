// CoordinateManifold (coordinate_manifold.h): Ceres' manifold invariants for
// linear, log, logit and log-logit coordinates, multiplicative log steps,
// intervals never left, rejection of points outside the domain.
#include <gtest/gtest.h>

#include <cmath>

#include <ceres/manifold_test_utils.h>

#include "diffpd/error.h"
#include "diffpd/solvers/ceres/coordinate_manifold.h"

namespace diffpd::solvers {
namespace {

using ceres::Vector;
// EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD names Ceres' matchers unqualified.
using namespace ceres;  // NOLINT

TEST(CoordinateManifoldTest, SatisfiesCeresManifoldInvariants) {
  const CoordinateManifold manifold({CoordinateMap::Log(), CoordinateMap::Linear(), CoordinateMap::Logit(0, 0.5),
                                     CoordinateMap::Logit(-1, 3), CoordinateMap::LogLogit(1e4, 5e6)});
  Vector x(5);
  x << 2e5, -0.3, 0.4, 2.5, 3e4;
  for (int k = 0; k < 3; ++k) {
    Vector delta(5), y(5);
    delta << 0.1 * k, -0.2 * k, 0.3 * k - 0.4, 1.0 - k, 0.5 * k - 0.7;
    y << 3e5 - 5e4 * k, 0.1 * k, 0.05 + 0.1 * k, -0.5 + k, 2e4 + 1e6 * k;
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-9);
  }
}

TEST(CoordinateManifoldTest, LogStepsAreMultiplicativeAndLogitStaysInside) {
  const CoordinateManifold manifold({CoordinateMap::Log(), CoordinateMap::Logit(0, 0.5)});
  const double x[2] = {2e5, 0.25};
  const double delta[2] = {std::log(2.0), 0.0};
  double y[2];
  ASSERT_TRUE(manifold.Plus(x, delta, y));
  EXPECT_DOUBLE_EQ(y[0], 4e5);
  EXPECT_DOUBLE_EQ(y[1], 0.25);
  const double huge[2] = {-800, 800};
  ASSERT_TRUE(manifold.Plus(x, huge, y));
  EXPECT_GE(y[0], 0.0);
  EXPECT_LE(y[1], 0.5);
  double j[4];
  ASSERT_TRUE(manifold.PlusJacobian(x, j));
  EXPECT_EQ(j[0], 2e5);
  EXPECT_EQ(j[1], 0.0);
  EXPECT_EQ(j[2], 0.0);
  EXPECT_DOUBLE_EQ(j[3], 0.25 * 0.25 / 0.5);
  const double outside[2] = {2e5, 0.5};
  EXPECT_FALSE(manifold.Plus(outside, delta, y));
  EXPECT_FALSE(manifold.PlusJacobian(outside, j));
  EXPECT_FALSE(manifold.Minus(x, outside, y));
  const double negative[2] = {-1.0, 0.3};
  EXPECT_FALSE(manifold.MinusJacobian(negative, j));
}

// log x is a logit coordinate of (log lo, log hi): the midpoint of the
// logarithms at u = 0, the ends for huge steps, relative steps inside.
TEST(CoordinateManifoldTest, LogLogitIsALogitOfTheLogarithm) {
  const CoordinateManifold manifold({CoordinateMap::LogLogit(1e4, 1e6)});
  const double mid = 1e5, zero = 0;
  double y;
  ASSERT_TRUE(manifold.Plus(&mid, &zero, &y));
  EXPECT_DOUBLE_EQ(y, 1e5);
  const double up = 2.0;  // s(2) = 0.8808: log10 y = 4 + 2 * 0.8808
  ASSERT_TRUE(manifold.Plus(&mid, &up, &y));
  EXPECT_NEAR(std::log10(y), 4 + 2 / (1 + std::exp(-2.0)), 1e-12);
  const double huge[2] = {-800, 800};
  ASSERT_TRUE(manifold.Plus(&mid, &huge[0], &y));
  EXPECT_GE(y, 1e4);
  ASSERT_TRUE(manifold.Plus(&mid, &huge[1], &y));
  EXPECT_LE(y, 1e6);
  double j;
  ASSERT_TRUE(manifold.PlusJacobian(&mid, &j));
  EXPECT_NEAR(j, 1e5 * std::log(100.0) * 0.25, 1e-9);
  const double outside = 1e3;
  EXPECT_FALSE(manifold.Plus(&outside, &zero, &y));
  try {
    CoordinateManifold({CoordinateMap::LogLogit(0, 1)});
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "CoordinateManifold: coordinate 0 has the log-logit interval (0, 1): needs 0 < lower");
  }
}

TEST(CoordinateManifoldTest, RejectsEmptyListsAndIntervals) {
  EXPECT_THROW(CoordinateManifold({}), InvalidInputError);
  try {
    CoordinateManifold({CoordinateMap::Log(), CoordinateMap::Logit(0.5, 0.5)});
    FAIL();
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "CoordinateManifold: coordinate 1 has the empty interval (0.5, 0.5)");
  }
}

}  // namespace
}  // namespace diffpd::solvers
