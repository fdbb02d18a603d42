#include "material/density_kernels.h"

#include <algorithm>

#include "diffpd/error.h"
#include "material/isotropic_differential.h"
#include "material/projections.h"

namespace diffpd::internal {
namespace {

// Corotated energy in the singular-value frame with weights (mu, lambda);
// pd-corotated is the case lambda = 0.
double CorotatedEnergyAndStress(const Svd3& svd, double mu, double lambda, Mat3* stress) {
  const Vec3& s = svd.sigma;
  const double J = s.prod();
  if (stress != nullptr) {
    const Vec3 cofactor(s(1) * s(2), s(0) * s(2), s(0) * s(1));
    const Vec3 p = 2.0 * mu * (s - Vec3::Ones()) + lambda * (J - 1.0) * cofactor;
    *stress = svd.U * p.asDiagonal() * svd.V.transpose();
  }
  return mu * (s - Vec3::Ones()).squaredNorm() + 0.5 * lambda * (J - 1.0) * (J - 1.0);
}

IsotropicDifferentialCoefficients CorotatedCoefficients(const Svd3& svd, double mu, double lambda) {
  // p_i = 2 mu (sigma_i - 1) + lambda (J - 1) c_i, c_i = prod_{j != i} sigma_j:
  //   dp_i/dsigma_i = 2 mu + lambda c_i^2,
  //   dp_i/dsigma_j = lambda (c_i c_j + (J - 1) sigma_k),
  //   c^sym_ij = 2 mu - lambda (J - 1) sigma_k,
  //   c^skew_ij = 2 mu (1 - 2 / (sigma_i + sigma_j)) + lambda (J - 1) sigma_k,
  // with k the third index; only the rotation term 2 / (sigma_i + sigma_j)
  // is singular (denominator floored as in RotationProjectionDifferential).
  const Vec3& s = svd.sigma;
  const double J = s.prod();
  const Vec3 cofactor(s(1) * s(2), s(0) * s(2), s(0) * s(1));
  IsotropicDifferentialCoefficients c;
  c.dp_dsigma = lambda * cofactor * cofactor.transpose();
  const double floor = DenominatorFloor(s);
  for (int pair = 0; pair < 3; ++pair) {
    const int i = kPairFirst[pair], j = kPairSecond[pair], k = 3 - i - j;
    c.dp_dsigma(i, j) += lambda * (J - 1.0) * s(k);
    c.dp_dsigma(j, i) += lambda * (J - 1.0) * s(k);
    c.symmetric(pair) = 2.0 * mu - lambda * (J - 1.0) * s(k);
    c.skew(pair) = 2.0 * mu * (1.0 - 2.0 / std::max(s(i) + s(j), floor)) + lambda * (J - 1.0) * s(k);
  }
  c.dp_dsigma.diagonal().array() += 2.0 * mu;
  return c;
}

double VolumeEnergyAndStress(const Svd3& svd, double lambda, Mat3* stress, const VolumeProjection* volume) {
  const Vec3 residual = svd.sigma - (volume ? volume->d : ProjectSingularValuesToUnitDeterminant(svd.sigma).d);
  if (stress != nullptr) {
    *stress = svd.U * (lambda * residual).asDiagonal() * svd.V.transpose();
  }
  return 0.5 * lambda * residual.squaredNorm();
}

IsotropicDifferentialCoefficients VolumeCoefficients(const Svd3& svd, double lambda, const VolumeProjection* volume) {
  // lambda (I - dProj/dF): the coefficients of the identity are (I, 1, 1).
  const VolumeProjection projection = volume ? *volume : ProjectSingularValuesToUnitDeterminant(svd.sigma);
  IsotropicDifferentialCoefficients c = UnitDeterminantProjectionCoefficients(svd.sigma, projection);
  c.dp_dsigma = lambda * (Mat3::Identity() - c.dp_dsigma);
  c.symmetric = lambda * (Vec3::Ones() - c.symmetric);
  c.skew = lambda * (Vec3::Ones() - c.skew);
  return c;
}

[[noreturn]] void NotProjective(ElasticEnergy energy) {
  DIFFPD_CHECK(false, "energy " << ToString(energy) << " has no PD projection");
}

}  // namespace

bool NeedsSvd(ElasticEnergy energy) {
  return energy == ElasticEnergy::kCorotated || energy == ElasticEnergy::kPdCorotated ||
         energy == ElasticEnergy::kPdVolume;
}

double Energy(ElasticEnergy energy, const Mat3& F, double mu, double lambda) {
  const Svd3 svd = NeedsSvd(energy) ? ComputeSvd3(F) : Svd3{};
  return EnergyAndStress(energy, F, svd, mu, lambda, nullptr);
}

Mat3 Stress(ElasticEnergy energy, const Mat3& F, double mu, double lambda) {
  const Svd3 svd = NeedsSvd(energy) ? ComputeSvd3(F) : Svd3{};
  Mat3 stress;
  EnergyAndStress(energy, F, svd, mu, lambda, &stress);
  return stress;
}

Mat9 StressDifferential(ElasticEnergy energy, const Mat3& F, double mu, double lambda) {
  const Svd3 svd = NeedsSvd(energy) ? ComputeSvd3(F) : Svd3{};
  return StressDifferential(energy, F, svd, mu, lambda);
}

double EnergyAndStress(ElasticEnergy energy, const Mat3& F, const Svd3& svd, double mu, double lambda, Mat3* stress,
                       const VolumeProjection* volume) {
  switch (energy) {
    case ElasticEnergy::kCorotated:
      return CorotatedEnergyAndStress(svd, mu, lambda, stress);
    case ElasticEnergy::kPdCorotated:
      return CorotatedEnergyAndStress(svd, mu, 0.0, stress);
    case ElasticEnergy::kPdVolume:
      return VolumeEnergyAndStress(svd, lambda, stress, volume);
    case ElasticEnergy::kLinear:
    case ElasticEnergy::kNeoHookean:
      break;
  }
  if (stress != nullptr) *stress = ::diffpd::FirstPiolaStress(energy, F, mu, lambda);
  return ::diffpd::EnergyDensity(energy, F, mu, lambda);
}

Mat9 StressDifferential(ElasticEnergy energy, const Mat3& F, const Svd3& svd, double mu, double lambda) {
  if (NeedsSvd(energy))
    return AssembleIsotropicDifferential(svd, StressDifferentialCoefficients(energy, svd, mu, lambda));
  return ::diffpd::StressDifferential(energy, F, mu, lambda);
}

IsotropicDifferentialCoefficients StressDifferentialCoefficients(ElasticEnergy energy, const Svd3& svd, double mu,
                                                                 double lambda, const VolumeProjection* volume) {
  switch (energy) {
    case ElasticEnergy::kCorotated:
      return CorotatedCoefficients(svd, mu, lambda);
    case ElasticEnergy::kPdCorotated:
      return CorotatedCoefficients(svd, mu, 0.0);
    case ElasticEnergy::kPdVolume:
      return VolumeCoefficients(svd, lambda, volume);
    case ElasticEnergy::kLinear:
    case ElasticEnergy::kNeoHookean:
      break;
  }
  DIFFPD_CHECK(false, "energy " << ToString(energy) << " has no singular-value form");
}

double ProjectiveWeight(ElasticEnergy energy, double mu, double lambda) {
  if (energy == ElasticEnergy::kPdCorotated) return 2.0 * mu;
  if (energy == ElasticEnergy::kPdVolume) return lambda;
  NotProjective(energy);
}

Mat3 Projection(ElasticEnergy energy, const Svd3& svd) {
  if (energy == ElasticEnergy::kPdCorotated) return ProjectToRotation(svd);
  if (energy == ElasticEnergy::kPdVolume) return ProjectToUnitDeterminant(svd);
  NotProjective(energy);
}

Mat9 ProjectionDifferential(ElasticEnergy energy, const Svd3& svd) {
  if (energy == ElasticEnergy::kPdCorotated) return RotationProjectionDifferential(svd);
  if (energy == ElasticEnergy::kPdVolume) return UnitDeterminantProjectionDifferential(svd);
  NotProjective(energy);
}

}  // namespace diffpd::internal
