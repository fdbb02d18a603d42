// Tests of the public material API: parameter validation messages, Lame
// parameters and their derivatives, and every energy density's stress and
// stress differential against finite differences.
#include "diffpd/material.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "diffpd/error.h"
#include "util/expect_message.h"
#include "util/central_difference.h"
#include "util/deformation.h"

namespace diffpd {
namespace {

const std::vector<ElasticEnergy> kEnergies = {ElasticEnergy::kLinear, ElasticEnergy::kCorotated,
                                              ElasticEnergy::kNeoHookean, ElasticEnergy::kPdCorotated,
                                              ElasticEnergy::kPdVolume};
constexpr double kMu = 1.3, kLambda = 2.1;

Mat3 RandomRotation(std::mt19937& rng) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized().toRotationMatrix();
}

// Deformations with det F > 0: small ones around I and large ones with
// singular values in [0.2, 5].
std::vector<Mat3> RandomDeformations(std::mt19937& rng, int count) {
  std::uniform_real_distribution<double> small(-0.3, 0.3), large(0.2, 5.0);
  std::vector<Mat3> result;
  for (int n = 0; n < count; ++n) {
    Mat3 F = Mat3::Identity();
    if (n % 2 == 0) {
      for (int i = 0; i < 9; ++i) F(i) += small(rng);
    } else {
      F = RandomRotation(rng) * Vec3(large(rng), large(rng), large(rng)).asDiagonal() * RandomRotation(rng);
    }
    result.push_back(F);
  }
  return result;
}

std::string ValidationMessage(const MaterialParameters& parameters) {
  return testing::MessageOf<InvalidInputError>([&] { parameters.Validate(); });
}

TEST(MaterialParametersTest, DefaultsAreValid) { EXPECT_NO_THROW(MaterialParameters().Validate()); }

TEST(MaterialParametersTest, ValidationMessagesAreExact) {
  MaterialParameters p;
  p.youngs_modulus = 0.0;
  EXPECT_EQ(ValidationMessage(p), "youngs_modulus = 0 is invalid: must be finite and > 0 (Pa)");
  p.youngs_modulus = -1.0;
  EXPECT_EQ(ValidationMessage(p), "youngs_modulus = -1 is invalid: must be finite and > 0 (Pa)");
  p.youngs_modulus = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(ValidationMessage(p), "youngs_modulus = nan is invalid: must be finite and > 0 (Pa)");
  p.youngs_modulus = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ValidationMessage(p), "youngs_modulus = inf is invalid: must be finite and > 0 (Pa)");
  p = MaterialParameters();
  p.poissons_ratio = 0.5;
  EXPECT_EQ(ValidationMessage(p), "poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");
  p.poissons_ratio = -1.0;
  EXPECT_EQ(ValidationMessage(p), "poissons_ratio = -1 is invalid: must be finite and in (-1, 0.5)");
  p.poissons_ratio = std::numeric_limits<double>::infinity();
  EXPECT_EQ(ValidationMessage(p), "poissons_ratio = inf is invalid: must be finite and in (-1, 0.5)");
  p = MaterialParameters();
  p.density = 0.0;
  EXPECT_EQ(ValidationMessage(p), "density = 0 is invalid: must be finite and > 0 (kg/m^3)");
  p.density = -2.5e3;
  EXPECT_EQ(ValidationMessage(p), "density = -2500 is invalid: must be finite and > 0 (kg/m^3)");
}

TEST(MaterialParametersTest, LameParametersAndDerivatives) {
  MaterialParameters p;
  p.youngs_modulus = 1e6;
  p.poissons_ratio = 0.45;
  EXPECT_NEAR(p.mu(), 1e6 / 2.9, 1e-9);
  EXPECT_NEAR(p.lambda(), 1e6 * 0.45 / (1.45 * 0.1), 1e-7);
  // (mu, lambda) as functions of (E, nu); Jacobian rows mu, lambda.
  const auto lame = [](const VectorXd& e_nu) {
    const MaterialParameters q{e_nu(0), e_nu(1), 1e3};
    return Eigen::Vector2d(q.mu(), q.lambda()).eval();
  };
  for (double nu : {-0.9, -0.3, 0.0, 0.25, 0.45, 0.49}) {
    p.poissons_ratio = nu;
    double dmu_dE, dmu_dnu, dlambda_dE, dlambda_dnu;
    p.LameDerivatives(&dmu_dE, &dmu_dnu, &dlambda_dE, &dlambda_dnu);
    const VectorXd e_nu = Eigen::Vector2d(p.youngs_modulus, nu);
    testing::DifferenceOptions along_e;
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(lame, e_nu, Eigen::Vector2d(1, 0),
                                                                    Eigen::Vector2d(dmu_dE, dlambda_dE), along_e)))
        << "nu = " << nu;
    // nu's scale is its distance to the poles of lambda at -1 and 0.5.
    testing::DifferenceOptions along_nu;
    along_nu.input_scale = std::min(1 + nu, 0.5 - nu);
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(lame, e_nu, Eigen::Vector2d(0, 1),
                                                                    Eigen::Vector2d(dmu_dnu, dlambda_dnu), along_nu)))
        << "nu = " << nu;
  }
  double only_mu = 0.0;
  p.LameDerivatives(&only_mu, nullptr, nullptr, nullptr);  // unwanted outputs may be null
  EXPECT_GT(only_mu, 0.0);
}

TEST(ElasticEnergyTest, NamesAndProjectivity) {
  EXPECT_STREQ(ToString(ElasticEnergy::kLinear), "linear");
  EXPECT_STREQ(ToString(ElasticEnergy::kCorotated), "corotated");
  EXPECT_STREQ(ToString(ElasticEnergy::kNeoHookean), "neohookean");
  EXPECT_STREQ(ToString(ElasticEnergy::kPdCorotated), "pd-corotated");
  EXPECT_STREQ(ToString(ElasticEnergy::kPdVolume), "pd-volume");
  EXPECT_FALSE(IsProjective(ElasticEnergy::kLinear));
  EXPECT_FALSE(IsProjective(ElasticEnergy::kCorotated));
  EXPECT_FALSE(IsProjective(ElasticEnergy::kNeoHookean));
  EXPECT_TRUE(IsProjective(ElasticEnergy::kPdCorotated));
  EXPECT_TRUE(IsProjective(ElasticEnergy::kPdVolume));
}

TEST(ElasticEnergyTest, ZeroEnergyAndStressAtRest) {
  for (ElasticEnergy energy : kEnergies) {
    EXPECT_NEAR(EnergyDensity(energy, Mat3::Identity(), kMu, kLambda), 0.0, 1e-15) << ToString(energy);
    EXPECT_LE(FirstPiolaStress(energy, Mat3::Identity(), kMu, kLambda).norm(), 1e-14) << ToString(energy);
  }
}

TEST(ElasticEnergyTest, StressIsTheEnergyGradient) {
  std::mt19937 rng(41);
  for (ElasticEnergy energy : kEnergies) {
    const auto psi = [&](const VectorXd& f) { return EnergyDensity(energy, testing::Unflatten(f), kMu, kLambda); };
    for (const Mat3& F : RandomDeformations(rng, 40)) {
      const Vec9 stress = testing::Flatten(FirstPiolaStress(energy, F, kMu, kLambda));
      testing::DifferenceOptions options;
      options.input_scale = testing::DeformationScale(F);
      EXPECT_TRUE(testing::Passes(testing::CheckGradient(psi, testing::Flatten(F), stress, options)))
          << ToString(energy) << " at F =\n"
          << F;
    }
  }
}

TEST(ElasticEnergyTest, StressDifferentialIsTheStressJacobian) {
  std::mt19937 rng(42);
  for (ElasticEnergy energy : kEnergies) {
    const auto stress = [&](const VectorXd& f) -> VectorXd {
      return testing::Flatten(FirstPiolaStress(energy, testing::Unflatten(f), kMu, kLambda));
    };
    for (const Mat3& F : RandomDeformations(rng, 40)) {
      const Mat9 analytic = StressDifferential(energy, F, kMu, kLambda);
      testing::DifferenceOptions options;
      options.input_scale = testing::DeformationScale(F);
      EXPECT_TRUE(testing::Passes(testing::CheckJacobian(stress, testing::Flatten(F), analytic, options)))
          << ToString(energy) << " at F =\n"
          << F;
    }
  }
}

TEST(ElasticEnergyTest, LinearInLameParameters) {
  std::mt19937 rng(43);
  for (ElasticEnergy energy : kEnergies) {
    for (const Mat3& F : RandomDeformations(rng, 10)) {
      const double e_mu = EnergyDensity(energy, F, 1.0, 0.0);
      const double e_lambda = EnergyDensity(energy, F, 0.0, 1.0);
      const double e = EnergyDensity(energy, F, kMu, kLambda);
      EXPECT_NEAR(e, kMu * e_mu + kLambda * e_lambda, 1e-12 * std::max(1.0, std::abs(e)));
      const Mat3 P = FirstPiolaStress(energy, F, kMu, kLambda);
      const Mat3 P_sum = kMu * FirstPiolaStress(energy, F, 1.0, 0.0) + kLambda * FirstPiolaStress(energy, F, 0.0, 1.0);
      EXPECT_LE((P - P_sum).norm(), 1e-12 * std::max(1.0, P.norm()));
      const Mat9 D = StressDifferential(energy, F, kMu, kLambda);
      const Mat9 D_sum =
          kMu * StressDifferential(energy, F, 1.0, 0.0) + kLambda * StressDifferential(energy, F, 0.0, 1.0);
      EXPECT_LE((D - D_sum).norm(), 1e-12 * std::max(1.0, D.norm()));
    }
  }
}

TEST(ElasticEnergyTest, RotationInvariance) {
  // Every energy but the linear one (whose strain is not rotation invariant).
  std::mt19937 rng(44);
  for (ElasticEnergy energy : kEnergies) {
    if (energy == ElasticEnergy::kLinear) continue;
    for (const Mat3& F : RandomDeformations(rng, 20)) {
      const Mat3 Q = RandomRotation(rng);
      const double e = EnergyDensity(energy, F, kMu, kLambda);
      EXPECT_NEAR(EnergyDensity(energy, Q * F, kMu, kLambda), e, 1e-11 * std::max(1.0, e)) << ToString(energy);
      EXPECT_NEAR(EnergyDensity(energy, F * Q, kMu, kLambda), e, 1e-11 * std::max(1.0, e)) << ToString(energy);
      EXPECT_LE((FirstPiolaStress(energy, Q * F, kMu, kLambda) - Q * FirstPiolaStress(energy, F, kMu, kLambda)).norm(),
                1e-11 * std::max(1.0, e));
    }
  }
}

TEST(ElasticEnergyTest, InvertedElementsForNonNeoHookeanEnergies) {
  // The other energies are defined (and differentiable) for det F < 0.
  std::mt19937 rng(45);
  for (ElasticEnergy energy : kEnergies) {
    if (energy == ElasticEnergy::kNeoHookean) continue;
    for (const Mat3& F0 : RandomDeformations(rng, 10)) {
      const Mat3 F = F0 * Vec3(1.0, 1.0, -0.5).asDiagonal();
      EXPECT_TRUE(std::isfinite(EnergyDensity(energy, F, kMu, kLambda)));
      EXPECT_TRUE(StressDifferential(energy, F, kMu, kLambda).allFinite());
    }
  }
}

TEST(ElasticEnergyTest, NeoHookeanRejectsInvertedElements) {
  for (const Vec3& diagonal : {Vec3(1.0, 1.0, -1.0), Vec3(2.0, 0.5, 0.0)}) {
    const Mat3 F = diagonal.asDiagonal();
    const std::string expected = diagonal(2) < 0 ? "neohookean energy: det F = -1 <= 0 (inverted element)"
                                                 : "neohookean energy: det F = 0 <= 0 (inverted element)";
    try {
      EnergyDensity(ElasticEnergy::kNeoHookean, F, kMu, kLambda);
      ADD_FAILURE() << "no exception";
    } catch (const SolverError& error) {
      EXPECT_EQ(error.status(), SolverStatus::kInvertedElement);
      EXPECT_EQ(std::string(error.what()), expected);
    }
    EXPECT_THROW(FirstPiolaStress(ElasticEnergy::kNeoHookean, F, kMu, kLambda), SolverError);
    EXPECT_THROW(StressDifferential(ElasticEnergy::kNeoHookean, F, kMu, kLambda), SolverError);
  }
}

}  // namespace
}  // namespace diffpd
