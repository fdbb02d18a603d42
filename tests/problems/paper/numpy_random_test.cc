// NumpyRandom reproduces numpy's legacy MT19937 stream (paper/numpy_random.h).
#include "paper/numpy_random.h"

#include <gtest/gtest.h>

namespace diffpd::problems {
namespace {

TEST(NumpyRandomTest, FirstUniformsAfterSeed42AreNumpys) {
  NumpyRandom rng(42);
  EXPECT_EQ(rng.Uniform(), 0.3745401188473625);
  EXPECT_EQ(rng.Uniform(), 0.9507143064099162);
}

TEST(NumpyRandomTest, FirstNormalsAfterSeed42AreNumpysIncludingTheCachedSecond) {
  NumpyRandom rng(42);
  EXPECT_EQ(rng.Normal(), 0.4967141530112327);
  EXPECT_EQ(rng.Normal(), -0.13826430117118466);  // the pair's cached value
  EXPECT_EQ(rng.Normal(), 0.6476885381006925);
}

TEST(NumpyRandomTest, UniformWithBoundsScalesTheSameDraws) {
  NumpyRandom a(42), b(42);
  EXPECT_EQ(a.Uniform(2.0, 4.0), 2.0 + 2.0 * b.Uniform());
  const VectorXd draws = a.Uniform(Eigen::Vector2d(0, -1), Eigen::Vector2d(1, 1));
  EXPECT_EQ(draws(0), b.Uniform());
  EXPECT_EQ(draws(1), -1.0 + 2.0 * b.Uniform());
}

}  // namespace
}  // namespace diffpd::problems
