// Tests of the PD projections (rotation, unit determinant, sphere): they land
// in their set, are idempotent, are the closest point, commute with rotations,
// and their differentials match central finite differences.
#include "material/projections.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "material/svd3.h"
#include "util/central_difference.h"
#include "util/deformation.h"

namespace diffpd::internal {
namespace {

using Projector = std::function<Mat3(const Mat3&)>;

Mat3 RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
}

// Q1 diag(sigma) Q2 with sigma_i uniform in [lo, hi] (random signs if signed).
Mat3 RandomDeformation(std::mt19937& rng, double lo, double hi) {
  std::uniform_real_distribution<double> uniform(lo, hi);
  const Vec3 sigma(uniform(rng), uniform(rng), uniform(rng));
  return RandomRotation(rng) * sigma.asDiagonal() * RandomRotation(rng);
}

Mat3 Rotation(const Mat3& F) { return ProjectToRotation(ComputeSvd3(F)); }
Mat3 Volume(const Mat3& F) { return ProjectToUnitDeterminant(ComputeSvd3(F)); }

// dvec(proj(F)) / dvec(F) = `analytic` by central differences.
void ExpectDifferentialMatches(const Projector& proj, const Mat9& analytic, const Mat3& F) {
  const auto flat = [&](const VectorXd& f) -> VectorXd { return testing::Flatten(proj(testing::Unflatten(f))); };
  testing::DifferenceOptions options;
  options.input_scale = testing::DeformationScale(F);
  EXPECT_TRUE(testing::Passes(testing::CheckJacobian(flat, testing::Flatten(F), analytic, options)))
      << "F =\n"
      << F << "\nsigma = " << ComputeSvd3(F).sigma.transpose();
}

// ---- rotation -------------------------------------------------------------

TEST(RotationProjectionTest, InSetIdempotentAndInvariant) {
  std::mt19937 rng(11);
  for (int n = 0; n < 200; ++n) {
    const Mat3 F = RandomDeformation(rng, n % 2 ? -2.0 : 0.1, 3.0);
    const Mat3 R = Rotation(F);
    EXPECT_LE((R.transpose() * R - Mat3::Identity()).norm(), 1e-14);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
    EXPECT_LE((Rotation(R) - R).norm(), 1e-14);
    const Mat3 Q = RandomRotation(rng);
    EXPECT_LE((Rotation(Q * F) - Q * R).norm(), 1e-13);
    EXPECT_LE((Rotation(F * Q) - R * Q).norm(), 1e-13);
  }
}

TEST(RotationProjectionTest, IsTheClosestRotation) {
  std::mt19937 rng(12);
  std::normal_distribution<double> normal;
  for (int n = 0; n < 50; ++n) {
    const Mat3 F = RandomDeformation(rng, -2.0, 3.0);
    const Mat3 R = Rotation(F);
    const double distance = (F - R).norm();
    for (int m = 0; m < 200; ++m) {
      // Far samples and samples near R (R exp(small skew)).
      const Vec3 w = (m % 2 ? 1e-3 : 1.0) * Vec3(normal(rng), normal(rng), normal(rng));
      const Mat3 sample = m % 2 ? Mat3(R * Eigen::AngleAxisd(w.norm(), w.normalized())) : RandomRotation(rng);
      EXPECT_GE((F - sample).norm(), distance - 1e-12);
    }
  }
}

TEST(RotationProjectionTest, DifferentialMatchesFiniteDifferences) {
  std::mt19937 rng(13);
  for (int n = 0; n < 100; ++n) {
    Mat3 F = RandomDeformation(rng, 0.2, 5.0);
    if (n % 4 == 1) F = F * Vec3(1.0, 1.0, -1.0).asDiagonal();  // inverted
    if (n % 4 == 2) {                                           // near-repeated singular values
      F = RandomRotation(rng) * Vec3(1.3, 1.3 + 1e-9, 0.7).asDiagonal() * RandomRotation(rng);
    }
    ExpectDifferentialMatches(Rotation, RotationProjectionDifferential(ComputeSvd3(F)), F);
  }
  // Identity and a repeated spectrum.
  ExpectDifferentialMatches(Rotation, RotationProjectionDifferential(ComputeSvd3(Mat3::Identity())), Mat3::Identity());
}

TEST(RotationProjectionTest, DenominatorIsClampedWhereRotationIsDiscontinuous) {
  // Rank one: sigma_1 + sigma_2 = 0; the differential stays finite.
  const Mat3 F = Vec3(1.0, 0.0, 0.0).asDiagonal();
  const Mat9 D = RotationProjectionDifferential(ComputeSvd3(F));
  EXPECT_TRUE(D.allFinite());
  EXPECT_NEAR(D.norm(), 2.0 / (kProjectionDenominatorFloor * 1.0), 1e-6 / kProjectionDenominatorFloor);
}

// ---- unit determinant -----------------------------------------------------

TEST(VolumeProjectionTest, SatisfiesKktConditions) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> uniform(0.05, 6.0);
  for (int n = 0; n < 500; ++n) {
    Vec3 sigma(uniform(rng), uniform(rng), uniform(rng));
    std::sort(sigma.data(), sigma.data() + 3, std::greater<double>());
    if (n % 3 == 0) sigma(2) = -sigma(2);
    const VolumeProjection p = ProjectSingularValuesToUnitDeterminant(sigma);
    EXPECT_NEAR(p.d.prod(), 1.0, 1e-14) << sigma.transpose();
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(p.d(i) - sigma(i), p.multiplier * p.d.prod() / p.d(i), 1e-12 * (1 + sigma.norm()))
          << sigma.transpose();
    }
  }
}

// Brute force: the closest point on {d0 d1 d2 = 1} over a log-spaced grid
// of (|d0|, |d1|) and the sign patterns of positive product.
double BruteForceDistance(const Vec3& sigma) {
  static const std::vector<double> grid = [] {
    std::vector<double> values;
    for (int a = -375; a <= 375; ++a) values.push_back(std::pow(10.0, a / 25.0));
    return values;
  }();
  // Plain scalars: 2.3 million points per spectrum, which unoptimised and
  // sanitized builds of this file evaluate 20-50x faster than with Eigen's
  // expression templates.
  double best_squared = std::numeric_limits<double>::infinity();
  const double signs[4][3] = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}};
  const double s0 = sigma(0), s1 = sigma(1), s2 = sigma(2);
  for (const auto& sign : signs) {
    for (const double d0 : grid) {
      const double e0 = sign[0] * d0 - s0;
      for (const double d1 : grid) {
        const double e1 = sign[1] * d1 - s1, e2 = sign[2] / (d0 * d1) - s2;
        best_squared = std::min(best_squared, e0 * e0 + e1 * e1 + e2 * e2);
      }
    }
  }
  return std::sqrt(best_squared);
}

TEST(VolumeProjectionTest, IsTheGlobalMinimiserOnHardSpectra) {
  const std::vector<Vec3> spectra = {{1, 1, 1},        {2, 1, 0.5},      {1.9, 1.9, 1.9}, {1.95, 1.9, 1.85},
                                     {2, 2, 2},        {10, 10, 10},     {10, 3, 1},      {5, 5, 4},
                                     {1, 1, -1},       {1, 1, 0},        {1, 0, 0},       {0, 0, 0},
                                     {3, 2, -2},       {0.5, 0.2, -0.1}, {1e3, 1, 1e-3},  {1e6, 1e-6, 1e-6},
                                     {1e6, 1e6, 1e-6}, {1e3, 1e3, 1e3},  {0.1, 0.1, 0.1}, {4, 0.3, -0.3}};
  for (const Vec3& sigma : spectra) {
    const VolumeProjection p = ProjectSingularValuesToUnitDeterminant(sigma);
    EXPECT_NEAR(p.d.prod(), 1.0, 1e-13) << sigma.transpose();
    const double distance = (p.d - sigma).norm();
    EXPECT_LE(distance, BruteForceDistance(sigma) * (1 + 1e-12)) << sigma.transpose() << " -> " << p.d.transpose();
  }
}

// The common case (all sigma > 0, prod < 2) takes a Halley iteration on the
// multiplier: it must give the global minimiser to rounding from
// infinitesimal strains up to the edge of its domain (prod just below 2,
// where the general path takes over), including strongly anisotropic spectra.
TEST(VolumeProjectionTest, PositiveSpectraBelowProductTwoAreProjectedToRounding) {
  const std::vector<Vec3> spectra = {{1 + 1e-12, 1, 1 - 1e-12},
                                     {1 + 1e-6, 1 - 1e-7, 1 - 2e-6},
                                     {1.02, 0.99, 0.97},
                                     {1.2599, 1.2599, 1.2599},
                                     {1.9, 1.01, 1.04},
                                     {1.5, 1.15, 1.15},
                                     {30, 0.2, 0.1},
                                     {1e4, 1e-2, 1e-3},
                                     {0.3, 0.2, 0.01}};
  for (const Vec3& sigma : spectra) {
    ASSERT_LT(sigma.prod(), 2.0);
    const VolumeProjection p = ProjectSingularValuesToUnitDeterminant(sigma);
    EXPECT_NEAR(p.d.prod(), 1.0, 4e-15) << sigma.transpose();
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(p.d(i) * (p.d(i) - sigma(i)), p.multiplier, 1e-14 * (1 + sigma.squaredNorm())) << sigma.transpose();
    }
    EXPECT_LE((p.d - sigma).norm(), BruteForceDistance(sigma) * (1 + 1e-12)) << sigma.transpose();
  }
}

// The batched projection solves the common case lane by lane and hands the
// others (inverted, large expansion, non-finite) to the single call: every
// lane must match ProjectSingularValuesToUnitDeterminant to rounding.
TEST(VolumeProjectionTest, BatchMatchesSingleCallsLaneByLane) {
  std::mt19937 rng(24);
  std::uniform_real_distribution<double> strain(-0.3, 0.3);
  for (int trial = 0; trial < 300; ++trial) {
    const int count = 1 + trial % kVolumeBatch;
    Vec3 sigma[kVolumeBatch];
    for (int l = 0; l < count; ++l) {
      for (int i = 0; i < 3; ++i) sigma[l](i) = 1.0 + strain(rng) * (trial % 3 == 0 ? 1e-4 : 1.0);
      std::sort(sigma[l].data(), sigma[l].data() + 3, std::greater<double>());
    }
    const int odd = count / 2;
    if (trial % 5 == 1) sigma[odd](2) = -sigma[odd](2);    // inverted
    if (trial % 5 == 2) sigma[odd] = Vec3(2.0, 1.9, 1.8);  // prod >= 2: general path
    if (trial % 5 == 3) sigma[odd](0) = std::numeric_limits<double>::infinity();
    VolumeProjection batch[kVolumeBatch];
    ProjectSingularValuesToUnitDeterminantBatch(count, sigma, batch);
    for (int l = 0; l < count; ++l) {
      const VolumeProjection single = ProjectSingularValuesToUnitDeterminant(sigma[l]);
      if (!sigma[l].allFinite()) {
        EXPECT_TRUE(batch[l].d.array().isNaN().all());
        continue;
      }
      EXPECT_LE((batch[l].d - single.d).norm(), 1e-14) << "trial " << trial << " lane " << l;
      EXPECT_NEAR(batch[l].multiplier, single.multiplier, 1e-14) << "trial " << trial << " lane " << l;
      EXPECT_NEAR(batch[l].d.prod(), 1.0, 4e-15);
    }
  }
}

TEST(VolumeProjectionTest, InSetIdempotentInvariantAndClosest) {
  std::mt19937 rng(22);
  std::normal_distribution<double> normal;
  for (int n = 0; n < 200; ++n) {
    const Mat3 F = RandomDeformation(rng, n % 2 ? -2.0 : 0.2, 3.0);
    const Mat3 P = Volume(F);
    EXPECT_NEAR(P.determinant(), 1.0, 1e-13);
    EXPECT_LE((Volume(P) - P).norm(), 1e-13 * P.norm());
    const Mat3 Q = RandomRotation(rng);
    EXPECT_LE((Volume(Q * F) - Q * P).norm(), 1e-12 * P.norm());
    EXPECT_LE((Volume(F * Q) - P * Q).norm(), 1e-12 * P.norm());
    const double distance = (F - P).norm();
    for (int m = 0; m < 100; ++m) {
      Mat3 sample;
      for (int i = 0; i < 9; ++i) sample(i) = normal(rng);
      if (m % 2) sample = P + 1e-3 * sample;  // near P
      const double det = sample.determinant();
      if (det == 0.0) continue;
      sample /= std::cbrt(det);  // on the set
      EXPECT_GE((F - sample).norm(), distance - 1e-12);
    }
  }
}

TEST(VolumeProjectionTest, DifferentialMatchesFiniteDifferences) {
  std::mt19937 rng(23);
  for (int n = 0; n < 200; ++n) {
    Mat3 F = RandomDeformation(rng, 0.2, 5.0);
    if (n % 4 == 1) F = F * Vec3(1.0, 1.0, -1.0).asDiagonal();  // inverted
    if (n % 4 == 2) {                                           // near-repeated singular values
      const double s = 0.5 + n / 100.0;
      F = RandomRotation(rng) * Vec3(s + 1e-9, s, 0.8).asDiagonal() * RandomRotation(rng);
    }
    if (n % 4 == 3) F = Mat3::Identity() + 0.1 * RandomDeformation(rng, -1.0, 1.0);
    ExpectDifferentialMatches(Volume, UnitDeterminantProjectionDifferential(ComputeSvd3(F)), F);
  }
}

TEST(VolumeProjectionTest, SingularValueJacobianMatchesFiniteDifferences) {
  // (Not at ties between minimisers such as sigma = (10, 10, 10), where the
  // projection jumps.)
  const std::vector<Vec3> spectra = {{2, 1, 0.5}, {1.9, 1.9, 1.9}, {3, 2, -1},    {10, 9, 8},
                                     {1, 1, 1},   {1e3, 1, 1e-3},  {4, 0.3, -0.2}};
  const auto project = [](const VectorXd& s) -> VectorXd { return ProjectSingularValuesToUnitDeterminant(s).d; };
  for (const Vec3& sigma : spectra) {
    const Mat3 J = UnitDeterminantProjectionJacobian(sigma, ProjectSingularValuesToUnitDeterminant(sigma));
    for (int j = 0; j < 3; ++j) {
      // Column by column: each singular value is its own input scale
      // (sigma spans 1e-3 .. 1e3 here).
      // The test's own floor 1e-6 (an absolute error of 1e-6 accepted for
      // columns below 1, e.g. d d / d sigma_2 = 1e-3 at sigma_2 = 1e-3, whose
      // noise floor would be 1e-4).
      testing::DifferenceOptions options;
      options.input_scale = std::abs(sigma(j));
      options.floor = 1e-6;
      const VectorXd column = J.col(j);
      EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(project, sigma, Vec3::Unit(j), column, options)))
          << sigma.transpose() << " column " << j;
    }
  }
}

// ---- sphere ---------------------------------------------------------------

TEST(SphereProjectionTest, ProjectionAndDifferential) {
  std::mt19937 rng(31);
  std::normal_distribution<double> normal;
  const double radius = 1.7;
  for (int n = 0; n < 100; ++n) {
    const Vec3 f(normal(rng), normal(rng), normal(rng));
    const Vec3 p = ProjectToSphere(f, radius);
    EXPECT_NEAR(p.norm(), radius, 1e-14);
    EXPECT_LE((ProjectToSphere(p, radius) - p).norm(), 1e-14);
    EXPECT_LE((p - f.normalized() * radius).norm(), 1e-14);
    const auto sphere = [&](const VectorXd& g) -> VectorXd { return ProjectToSphere(g, radius); };
    EXPECT_TRUE(testing::Passes(testing::CheckJacobian(sphere, f, SphereProjectionDifferential(f, radius))))
        << "f = " << f.transpose();
  }
  EXPECT_EQ(ProjectToSphere(Vec3::Zero(), radius), Vec3(radius, 0.0, 0.0));
  EXPECT_EQ(SphereProjectionDifferential(Vec3::Zero(), radius), Mat3::Zero());
}

}  // namespace
}  // namespace diffpd::internal
