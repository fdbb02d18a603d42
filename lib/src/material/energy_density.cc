// Reference energy densities, first Piola-Kirchhoff stresses and stress
// differentials, written directly from the formulas of material.h in terms of
// F (the solvers use the SVD-based kernels of density_kernels.h, which are
// tested against these).
#include <cmath>
#include <sstream>

#include <Eigen/LU>

#include "diffpd/error.h"
#include "diffpd/material.h"
#include "material/cofactor.h"
#include "material/projections.h"
#include "material/svd3.h"

namespace diffpd {
namespace {

using internal::Cofactor;
using internal::CofactorDifferential;

Vec9 Flatten(const Mat3& A) { return Eigen::Map<const Vec9>(A.data()); }

// J = det F > 0 or throws SolverError(kInvertedElement).
double NeoHookeanDeterminant(const Mat3& F) {
  const double J = F.determinant();
  if (!(J > 0.0)) {
    std::ostringstream message;
    message << "neohookean energy: det F = " << J << " <= 0 (inverted element)";
    throw SolverError(SolverStatus::kInvertedElement, message.str());
  }
  return J;
}

[[noreturn]] void UnknownEnergy(ElasticEnergy energy) {
  DIFFPD_CHECK(false, "unknown ElasticEnergy " << static_cast<int>(energy));
}

}  // namespace

double EnergyDensity(ElasticEnergy energy, const Mat3& F, double mu, double lambda) {
  switch (energy) {
    case ElasticEnergy::kLinear: {
      const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
      const double trace = eps.trace();
      return mu * eps.squaredNorm() + 0.5 * lambda * trace * trace;
    }
    case ElasticEnergy::kCorotated: {
      const Mat3 R = internal::ProjectToRotation(internal::ComputeSvd3(F));
      const double J = F.determinant();
      return mu * (F - R).squaredNorm() + 0.5 * lambda * (J - 1.0) * (J - 1.0);
    }
    case ElasticEnergy::kNeoHookean: {
      const double log_J = std::log(NeoHookeanDeterminant(F));
      return 0.5 * mu * (F.squaredNorm() - 3.0) - mu * log_J + 0.5 * lambda * log_J * log_J;
    }
    case ElasticEnergy::kPdCorotated:
      return mu * (F - internal::ProjectToRotation(internal::ComputeSvd3(F))).squaredNorm();
    case ElasticEnergy::kPdVolume:
      return 0.5 * lambda * (F - internal::ProjectToUnitDeterminant(internal::ComputeSvd3(F))).squaredNorm();
  }
  UnknownEnergy(energy);
}

Mat3 FirstPiolaStress(ElasticEnergy energy, const Mat3& F, double mu, double lambda) {
  switch (energy) {
    case ElasticEnergy::kLinear: {
      const Mat3 eps = 0.5 * (F + F.transpose()) - Mat3::Identity();
      return 2.0 * mu * eps + lambda * eps.trace() * Mat3::Identity();
    }
    case ElasticEnergy::kCorotated: {
      const Mat3 R = internal::ProjectToRotation(internal::ComputeSvd3(F));
      return 2.0 * mu * (F - R) + lambda * (F.determinant() - 1.0) * Cofactor(F);
    }
    case ElasticEnergy::kNeoHookean: {
      const double J = NeoHookeanDeterminant(F);
      const Mat3 F_inv_T = F.inverse().transpose();
      return mu * (F - F_inv_T) + lambda * std::log(J) * F_inv_T;
    }
    case ElasticEnergy::kPdCorotated:
      return 2.0 * mu * (F - internal::ProjectToRotation(internal::ComputeSvd3(F)));
    case ElasticEnergy::kPdVolume:
      return lambda * (F - internal::ProjectToUnitDeterminant(internal::ComputeSvd3(F)));
  }
  UnknownEnergy(energy);
}

Mat9 StressDifferential(ElasticEnergy energy, const Mat3& F, double mu, double lambda) {
  const Mat9 identity = Mat9::Identity();
  switch (energy) {
    case ElasticEnergy::kLinear: {
      // dP = 2 mu sym(dF) + lambda tr(dF) I.
      Mat9 D = Mat9::Zero();
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
          D(i + 3 * j, i + 3 * j) += mu;
          D(i + 3 * j, j + 3 * i) += mu;
          D(i + 3 * i, j + 3 * j) += lambda;
        }
      }
      return D;
    }
    case ElasticEnergy::kCorotated: {
      const Mat9 dR = internal::RotationProjectionDifferential(internal::ComputeSvd3(F));
      const Vec9 cofactor = Flatten(Cofactor(F));
      return 2.0 * mu * (identity - dR) +
             lambda * (cofactor * cofactor.transpose() + (F.determinant() - 1.0) * CofactorDifferential(F));
    }
    case ElasticEnergy::kNeoHookean: {
      // dP = mu dF + (lambda log J - mu) d(F^-T) + lambda <F^-T, dF> F^-T,
      // d(F^-T)_ij / dF_kl = -(F^-1)_li (F^-1)_jk.
      const double log_J = std::log(NeoHookeanDeterminant(F));
      const Mat3 F_inv = F.inverse();
      const Vec9 F_inv_T = Flatten(F_inv.transpose());
      Mat9 D = mu * identity + lambda * F_inv_T * F_inv_T.transpose();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          for (int k = 0; k < 3; ++k)
            for (int l = 0; l < 3; ++l) D(i + 3 * j, k + 3 * l) += (mu - lambda * log_J) * F_inv(l, i) * F_inv(j, k);
      return D;
    }
    case ElasticEnergy::kPdCorotated:
      return 2.0 * mu * (identity - internal::RotationProjectionDifferential(internal::ComputeSvd3(F)));
    case ElasticEnergy::kPdVolume:
      return lambda * (identity - internal::UnitDeterminantProjectionDifferential(internal::ComputeSvd3(F)));
  }
  UnknownEnergy(energy);
}

}  // namespace diffpd
