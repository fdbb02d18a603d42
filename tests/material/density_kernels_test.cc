// Tests of the solver kernels against the reference densities of material.h,
// and of the PD form (w/2)|F - Proj(F)|^2 of the projective energies.
#include "material/density_kernels.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "diffpd/error.h"
#include "diffpd/material.h"
#include "material/svd3.h"

namespace diffpd::internal {
namespace {

const std::vector<ElasticEnergy> kEnergies = {ElasticEnergy::kLinear, ElasticEnergy::kCorotated,
                                              ElasticEnergy::kNeoHookean, ElasticEnergy::kPdCorotated,
                                              ElasticEnergy::kPdVolume};
constexpr double kMu = 1.3, kLambda = 2.1;

Mat3 RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
}

// Deformations with singular values in [0.2, 5], inverted (det < 0) when asked.
std::vector<Mat3> RandomDeformations(std::mt19937& rng, int count, bool inverted) {
  std::uniform_real_distribution<double> large(0.2, 5.0);
  std::vector<Mat3> result;
  for (int n = 0; n < count; ++n) {
    Vec3 sigma(large(rng), large(rng), large(rng));
    if (n % 3 == 0) sigma = Vec3::Ones() + 0.1 * (sigma / 5.0);  // near rest
    if (inverted) sigma(2) = -sigma(2);
    result.push_back(RandomRotation(rng) * sigma.asDiagonal() * RandomRotation(rng));
  }
  return result;
}

double Relative(double a, double b) { return std::abs(a - b) / std::max(1.0, std::abs(b)); }
template <class M>
double Relative(const M& a, const M& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

TEST(DensityKernelsTest, MatchReferenceImplementations) {
  std::mt19937 rng(51);
  for (ElasticEnergy energy : kEnergies) {
    for (bool inverted : {false, true}) {
      if (inverted && energy == ElasticEnergy::kNeoHookean) continue;
      for (const Mat3& F : RandomDeformations(rng, 30, inverted)) {
        const double e = EnergyDensity(energy, F, kMu, kLambda);
        const Mat3 P = FirstPiolaStress(energy, F, kMu, kLambda);
        const Mat9 D = ::diffpd::StressDifferential(energy, F, kMu, kLambda);
        EXPECT_LE(Relative(Energy(energy, F, kMu, kLambda), e), 1e-12) << ToString(energy);
        EXPECT_LE(Relative(Stress(energy, F, kMu, kLambda), P), 1e-12) << ToString(energy);
        EXPECT_LE(Relative(internal::StressDifferential(energy, F, kMu, kLambda), D), 1e-10)
            << ToString(energy) << " at F =\n"
            << F;
        const Svd3 svd = ComputeSvd3(F);
        Mat3 stress;
        EXPECT_LE(Relative(EnergyAndStress(energy, F, svd, kMu, kLambda, &stress), e), 1e-12);
        EXPECT_LE(Relative(stress, P), 1e-12);
        EXPECT_LE(Relative(EnergyAndStress(energy, F, svd, kMu, kLambda, nullptr), e), 1e-12);
        EXPECT_LE(Relative(StressDifferential(energy, F, svd, kMu, kLambda), D), 1e-10);
      }
    }
  }
}

TEST(DensityKernelsTest, ProjectiveForm) {
  std::mt19937 rng(52);
  const Mat9 I = Mat9::Identity();
  for (ElasticEnergy energy : kEnergies) {
    EXPECT_EQ(NeedsSvd(energy), energy != ElasticEnergy::kLinear && energy != ElasticEnergy::kNeoHookean);
    if (!IsProjective(energy)) continue;
    const double w = ProjectiveWeight(energy, kMu, kLambda);
    EXPECT_EQ(w, energy == ElasticEnergy::kPdCorotated ? 2.0 * kMu : kLambda);
    for (const Mat3& F : RandomDeformations(rng, 20, false)) {
      const Svd3 svd = ComputeSvd3(F);
      const Mat3 proj = Projection(energy, svd);
      EXPECT_LE(Relative(Energy(energy, F, kMu, kLambda), 0.5 * w * (F - proj).squaredNorm()), 1e-12);
      EXPECT_LE(Relative(Stress(energy, F, kMu, kLambda), Mat3(w * (F - proj))), 1e-12);
      EXPECT_LE(Relative(internal::StressDifferential(energy, F, kMu, kLambda),
                         Mat9(w * (I - ProjectionDifferential(energy, svd)))),
                1e-10);
    }
  }
}

TEST(DensityKernelsTest, NeoHookeanKernelRejectsInvertedElements) {
  const Mat3 F = Vec3(1.0, 1.0, -1.0).asDiagonal();
  EXPECT_THROW(Energy(ElasticEnergy::kNeoHookean, F, kMu, kLambda), SolverError);
  EXPECT_THROW(Stress(ElasticEnergy::kNeoHookean, F, kMu, kLambda), SolverError);
  EXPECT_THROW(internal::StressDifferential(ElasticEnergy::kNeoHookean, F, kMu, kLambda), SolverError);
}

}  // namespace
}  // namespace diffpd::internal
