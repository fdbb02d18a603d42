// Tests of the trajectory functions (trajectory_function.h) on a synthetic
// rollout: values, gradients vs central differences, tracked points, errors.
#include "diffpd/solvers/core/trajectory_function.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

// A rollout of 3 steps over 4 nodes with pseudo-random states.
Rollout SyntheticRollout() {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Rollout r;
  r.inputs.resize(3);
  for (int k = 0; k <= 3; ++k) {
    State s;
    s.x = VectorXd(12);
    s.v = VectorXd(12);
    for (int i = 0; i < 12; ++i) {
      s.x(i) = u(rng);
      s.v(i) = u(rng);
    }
    r.states.push_back(s);
  }
  return r;
}

// Checks AddGradient against central differences in every position entry.
void ExpectGradientMatches(const TrajectoryFunction& f, Rollout r) {
  LossGradient loss(3);
  f.AddGradient(r, 2.0, &loss);
  const double eps = 1e-6;
  for (int k = 0; k <= 3; ++k)
    for (int i = 0; i < 12; ++i) {
      const double x = r.states[k].x(i);
      r.states[k].x(i) = x + eps;
      const double plus = f.Value(r);
      r.states[k].x(i) = x - eps;
      const double minus = f.Value(r);
      r.states[k].x(i) = x;
      const double fd = 2.0 * (plus - minus) / (2 * eps);
      const double analytic = loss.dx[k].size() ? loss.dx[k](i) : 0.0;
      EXPECT_NEAR(analytic, fd, 1e-8 * std::max(1.0, std::abs(fd))) << f.name() << " state " << k << " entry " << i;
    }
  for (const VectorXd& dv : loss.dv) EXPECT_EQ(dv.size(), 0);  // positions only
}

TEST(TrajectoryConstraintTest, TrackedPointsAreWeightedMeans) {
  VectorXd mass(12);
  mass << 1, 1, 1, 3, 3, 3, 0, 0, 0, 4, 4, 4;
  const TrackedPoint com = CentreOfMass(mass);
  EXPECT_NEAR(com.node_weights.sum(), 1.0, 1e-15);
  VectorXd x(12);
  x << 0, 0, 0, 1, 0, 0, 5, 5, 5, 0, 2, 0;
  EXPECT_TRUE(com.At(x).isApprox(Vec3(3.0 / 8, 1.0, 0.0)));
  EXPECT_TRUE(MeanOf(4, {1, 3}).At(x).isApprox(Vec3(0.5, 1.0, 0.0)));
  EXPECT_TRUE(NodePoint(4, 2).At(x).isApprox(Vec3(5, 5, 5)));
  try {
    NodePoint(4, 4);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "marker node 4 is out of range [0, 4)");
  }
}

TEST(TrajectoryConstraintTest, ValuesFollowTheirFormulas) {
  const Rollout r = SyntheticRollout();
  const TrackedPoint p = MeanOf(4, {0, 2});
  const Vec3 p1 = p.At(r.states[1].x), p3 = p.At(r.states[3].x), p0 = p.At(r.states[0].x);
  EXPECT_NEAR(PointCoordinate(p, 1, Vec3(0, 2, 0)).Value(r), 2 * p1.y(), 1e-15);
  EXPECT_NEAR(PointCoordinate(p, kFinalState, Vec3::UnitZ()).Value(r), p3.z(), 1e-15);
  EXPECT_NEAR(PointTravel(p, 0, kFinalState, Vec3::UnitX()).Value(r), p3.x() - p0.x(), 1e-15);
  const Vec3 t(0.1, 0.2, 0.3);
  EXPECT_NEAR(PointDistanceSquared(p, 3, t).Value(r), (p3 - t).squaredNorm(), 1e-15);
  EXPECT_NEAR(PointDistanceSquared(p, 3, t, "d", Vec3(1, 1, 0)).Value(r), (p3 - t).head<2>().squaredNorm(), 1e-15);
  const TrackedPoint a = NodePoint(4, 1), b = NodePoint(4, 3);
  const Vec3 d = b.At(r.states[2].x) - a.At(r.states[2].x);
  EXPECT_NEAR(AxisAlignment(a, b, 2, Vec3(0, 0, 5)).Value(r), d.z() / d.norm(), 1e-15);
  EXPECT_EQ(PointTravel(p, 0, 2, Vec3::UnitX()).LastState(7), 2);
  EXPECT_EQ(PointCoordinate(p, kFinalState, Vec3::UnitX()).LastState(7), 7);
}

TEST(TrajectoryConstraintTest, GradientsMatchCentralDifferences) {
  const Rollout r = SyntheticRollout();
  const TrackedPoint p = MeanOf(4, {0, 2, 3});
  ExpectGradientMatches(PointCoordinate(p, 2, Vec3(0.3, -1, 2)), r);
  ExpectGradientMatches(PointTravel(p, 1, kFinalState, Vec3(1, 0.5, 0)), r);
  ExpectGradientMatches(PointDistanceSquared(p, kFinalState, Vec3(0.1, 0.2, 0.3), "d", Vec3(1, 2, 0.5)), r);
  ExpectGradientMatches(AxisAlignment(NodePoint(4, 1), MeanOf(4, {2, 3}), 3, Vec3(0.2, 0.1, 1)), r);
}

TEST(TrajectoryConstraintTest, BadArgumentsAreRefusedWithMessages) {
  const TrackedPoint p = NodePoint(4, 0);
  try {
    PointCoordinate(p, -2, Vec3::UnitX(), "c");
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "c: step -2 is invalid: must be a state index >= 0 or kFinalState (-1)");
  }
  try {
    AxisAlignment(p, NodePoint(4, 1), 1, Vec3::Zero(), "up");
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "up: the direction must be finite and non-zero");
  }
  try {
    PointDistanceSquared(p, 1, Vec3::Zero(), "d", Vec3(1, -1, 0));
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "d: the axis weights must be finite and >= 0");
  }
  Rollout r = SyntheticRollout();
  try {
    PointCoordinate(p, 5, Vec3::UnitX(), "late").Value(r);
    FAIL() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "late: reads state 5 but the rollout has 4 states");
  }
}

}  // namespace
}  // namespace diffpd::solvers
