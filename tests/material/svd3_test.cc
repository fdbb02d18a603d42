// Tests of the signed 3x3 SVD: reconstruction, orthogonality, proper
// rotations, ordering and sign convention on special and random matrices.
#include "material/svd3.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <vector>

namespace diffpd::internal {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Allowed error, in units of eps (relative to |F| for the reconstruction).
constexpr double kUlps = 16.0;

Mat3 RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
}

// Checks every property of ComputeSvd3(F); returns the SVD for more checks.
Svd3 CheckSvd(const Mat3& F) {
  const Svd3 svd = ComputeSvd3(F);
  const Mat3 I = Mat3::Identity();
  EXPECT_LE((svd.U * svd.sigma.asDiagonal() * svd.V.transpose() - F).norm(), kUlps * kEps * F.norm()) << "F =\n" << F;
  EXPECT_LE((svd.U.transpose() * svd.U - I).norm(), kUlps * kEps) << "F =\n" << F;
  EXPECT_LE((svd.V.transpose() * svd.V - I).norm(), kUlps * kEps) << "F =\n" << F;
  EXPECT_NEAR(svd.U.determinant(), 1.0, kUlps * kEps);
  EXPECT_NEAR(svd.V.determinant(), 1.0, kUlps * kEps);
  EXPECT_GE(svd.sigma(0), svd.sigma(1)) << "F =\n" << F;
  EXPECT_GE(svd.sigma(1), std::abs(svd.sigma(2))) << "F =\n" << F;
  const double det = F.determinant();
  // The sign of det F is meaningful when it is not at round-off level.
  if (std::abs(det) > 1e3 * kEps * std::pow(F.norm(), 3)) {
    EXPECT_EQ(svd.sigma(2) < 0.0, det < 0.0) << "F =\n" << F;
  }
  return svd;
}

void CheckSingularValues(const Mat3& F, const Vec3& expected) {
  const Svd3 svd = CheckSvd(F);
  EXPECT_LE((svd.sigma - expected).norm(), kUlps * kEps * expected.norm())
      << "sigma = " << svd.sigma.transpose() << ", expected " << expected.transpose();
}

TEST(Svd3Test, IdentityIsExact) {
  const Svd3 svd = ComputeSvd3(Mat3::Identity());
  EXPECT_EQ(svd.sigma, Vec3::Ones());
  EXPECT_EQ(svd.U, Mat3::Identity());
  EXPECT_EQ(svd.V, Mat3::Identity());
}

TEST(Svd3Test, ZeroMatrix) {
  const Svd3 svd = CheckSvd(Mat3::Zero());
  EXPECT_EQ(svd.sigma, Vec3::Zero());
}

TEST(Svd3Test, DiagonalAndPermutations) {
  CheckSingularValues(Vec3(1.0, 2.0, 3.0).asDiagonal(), Vec3(3.0, 2.0, 1.0));
  CheckSingularValues(Vec3(-1.0, 2.0, 3.0).asDiagonal(), Vec3(3.0, 2.0, -1.0));
  CheckSingularValues(Vec3(-3.0, -2.0, 1.0).asDiagonal(), Vec3(3.0, 2.0, 1.0));
  CheckSingularValues(Vec3(-3.0, -2.0, -1.0).asDiagonal(), Vec3(3.0, 2.0, -1.0));
  Mat3 P;
  P << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  CheckSingularValues(P, Vec3::Ones());
  CheckSingularValues(-P, Vec3(1.0, 1.0, -1.0));
}

TEST(Svd3Test, ReflectionsHaveNegativeLastSingularValue) {
  std::mt19937 rng(1);
  for (int n = 0; n < 100; ++n) {
    const Mat3 reflection = RandomRotation(rng) * Vec3(1.0, 1.0, -1.0).asDiagonal();
    CheckSingularValues(reflection, Vec3(1.0, 1.0, -1.0));
    CheckSingularValues(reflection * Vec3(3.0, 2.0, 0.5).asDiagonal() * RandomRotation(rng), Vec3(3.0, 2.0, -0.5));
  }
}

TEST(Svd3Test, RepeatedRankDeficientAndScaled) {
  std::mt19937 rng(2);
  const std::vector<Vec3> spectra = {{1, 1, 1},     {2, 2, 1},     {2, 1, 1},         {1, 1, -1},   {2, 2, -2},
                                     {1, 1, 0},     {1, 0, 0},     {1, 1e-9, 1e-9},   {1, 1e-5, 0}, {1, 1 + 1e-12, 1},
                                     {3, 3, -1e-7}, {1, 0.5, 0.5}, {1 + 1e-15, 1, 1}, {0, 0, 0}};
  for (const Vec3& spectrum : spectra) {
    for (double scale : {1e-8, 1e-4, 1.0, 1e4, 1e8}) {
      for (int n = 0; n < 20; ++n) {
        Vec3 sorted = spectrum;
        std::sort(sorted.data(), sorted.data() + 2, std::greater<double>());
        const Mat3 F = RandomRotation(rng) * (scale * spectrum).asDiagonal() * RandomRotation(rng);
        const Svd3 svd = CheckSvd(F);
        EXPECT_LE((svd.sigma - scale * sorted).norm(), kUlps * kEps * scale * sorted.norm() + 1e-300)
            << "sigma = " << svd.sigma.transpose() << ", expected " << (scale * sorted).transpose();
      }
    }
  }
}

TEST(Svd3Test, RankOneOuterProducts) {
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  for (int n = 0; n < 200; ++n) {
    const Vec3 a(normal(rng), normal(rng), normal(rng));
    const Vec3 b(normal(rng), normal(rng), normal(rng));
    const Svd3 svd = CheckSvd(a * b.transpose());
    EXPECT_NEAR(svd.sigma(0), a.norm() * b.norm(), kUlps * kEps * a.norm() * b.norm());
    EXPECT_LE(std::abs(svd.sigma(1)), kUlps * kEps * a.norm() * b.norm());
  }
}

TEST(Svd3Test, ExtremeScalesAreRescaledExactly) {
  std::mt19937 rng(4);
  for (double scale : {1e-200, 1e-120, 1e120, 1e200}) {
    const Mat3 F = scale * RandomRotation(rng) * Vec3(3.0, 2.0, -1.0).asDiagonal() * RandomRotation(rng);
    const Svd3 svd = ComputeSvd3(F);
    EXPECT_LE((svd.U * svd.sigma.asDiagonal() * svd.V.transpose() - F).norm(), kUlps * kEps * F.norm());
    EXPECT_LE((svd.sigma / scale - Vec3(3.0, 2.0, -1.0)).norm(), kUlps * kEps * 4.0);
  }
}

TEST(Svd3Test, NonFiniteInputGivesNaN) {
  Mat3 F = Mat3::Identity();
  F(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(ComputeSvd3(F).sigma.array().isNaN().all());
  F(1, 2) = std::numeric_limits<double>::infinity();
  EXPECT_TRUE(ComputeSvd3(F).sigma.array().isNaN().all());
}

TEST(Svd3Test, TenThousandRandomMatrices) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::uniform_real_distribution<double> exponent(-8.0, 8.0);
  for (int n = 0; n < 10000; ++n) {
    Mat3 F;
    for (int i = 0; i < 9; ++i) F(i) = uniform(rng);
    if (n % 2 == 1) F *= std::pow(10.0, exponent(rng));
    if (n % 5 == 0) F = Mat3::Identity() + 0.01 * F;  // near-rest deformations
    CheckSvd(F);
  }
}

// The batched SVD runs every lane through the same rotations as the scalar
// one (converged lanes are rotated by exactly the identity), so each result
// must match ComputeSvd3(F, v_guess) to rounding, for warm and cold guesses,
// partial batches, and lanes that take the scalar path (zero, non-finite,
// extreme magnitude) mixed with regular ones.
TEST(Svd3Test, BatchMatchesScalarLaneByLane) {
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int trial = 0; trial < 400; ++trial) {
    const int count = 1 + trial % kSvdBatch;
    Mat3 F[kSvdBatch], guess[kSvdBatch];
    for (int l = 0; l < count; ++l) {
      for (int i = 0; i < 9; ++i) F[l](i) = uniform(rng);
      if ((trial + l) % 3 == 0) F[l] = Mat3::Identity() + 0.01 * F[l];
      // Warm guess: the V of a nearby matrix; else a random rotation or I.
      Mat3 nearby = F[l];
      nearby(0, 1) += 1e-3;
      guess[l] = (trial + l) % 4 == 0   ? Mat3(RandomRotation(rng))
                 : (trial + l) % 4 == 1 ? Mat3::Identity()
                                        : ComputeSvd3(nearby).V;
    }
    if (trial % 7 == 3) F[count / 2].setZero();
    if (trial % 7 == 4) F[count / 2](1, 1) = nan;
    if (trial % 7 == 5) F[count / 2] *= 1e150;
    if (trial % 7 == 6) F[count / 2] = Mat3(Vec3(1.0, 1.0, -1.0).asDiagonal());  // reflection
    Svd3 batch[kSvdBatch];
    ComputeSvd3Batch(count, F, guess, batch);
    for (int l = 0; l < count; ++l) {
      const Svd3 scalar = ComputeSvd3(F[l], guess[l]);
      if (!F[l].allFinite()) {
        EXPECT_TRUE(batch[l].sigma.array().isNaN().all());
        continue;
      }
      // The vector clones may contract a * b + c into one FMA where the
      // scalar code rounds twice: agreement to a few ulps, not bit for bit.
      const double scale = std::max(1.0, scalar.sigma(0));
      EXPECT_LE((batch[l].sigma - scalar.sigma).norm(), kUlps * kEps * scale) << "trial " << trial << " lane " << l;
      // U and V are unique (up to the sign convention) only for distinct
      // singular values.
      const Vec3& sg = scalar.sigma;
      if (std::min(sg(0) - sg(1), sg(1) - std::abs(sg(2))) > 1e-6 * scale) {
        EXPECT_LE((batch[l].U - scalar.U).norm(), 1e-11) << "trial " << trial << " lane " << l;
        EXPECT_LE((batch[l].V - scalar.V).norm(), 1e-11) << "trial " << trial << " lane " << l;
      }
      EXPECT_LE((batch[l].U * batch[l].sigma.asDiagonal() * batch[l].V.transpose() - F[l]).norm(),
                kUlps * kEps * F[l].norm());
      // V is the guess times exact-in-theory rotations: its orthogonality
      // error is the guess's plus the rotations' rounding.
      const double guess_error = (guess[l].transpose() * guess[l] - Mat3::Identity()).norm();
      EXPECT_LE((batch[l].V.transpose() * batch[l].V - Mat3::Identity()).norm(), guess_error + kUlps * kEps)
          << "trial " << trial << " lane " << l;
    }
  }
}

}  // namespace
}  // namespace diffpd::internal
