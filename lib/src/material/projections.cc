// Rotation, unit-determinant (matrix level) and sphere projections. The
// singular-value problem of the unit-determinant projection is solved in
// volume_projection.cc.
#include "material/projections.h"

#include <algorithm>
#include <cmath>

#include "material/isotropic_differential.h"

namespace diffpd::internal {

Mat3 ProjectToRotation(const Svd3& svd) { return svd.U * svd.V.transpose(); }

Mat9 RotationProjectionDifferential(const Svd3& svd) {
  // p = (1, 1, 1): only the skew modes contribute, with 2 / (sigma_i + sigma_j).
  IsotropicDifferentialCoefficients c;
  const double floor = DenominatorFloor(svd.sigma);
  for (int k = 0; k < 3; ++k) {
    c.skew(k) = 2.0 / std::max(svd.sigma(kPairFirst[k]) + svd.sigma(kPairSecond[k]), floor);
  }
  return AssembleIsotropicDifferential(svd, c);
}

Mat3 ProjectToUnitDeterminant(const Svd3& svd) {
  const Vec3 d = ProjectSingularValuesToUnitDeterminant(svd.sigma).d;
  return svd.U * d.asDiagonal() * svd.V.transpose();
}

Mat9 UnitDeterminantProjectionDifferential(const Svd3& svd) {
  const VolumeProjection projection = ProjectSingularValuesToUnitDeterminant(svd.sigma);
  return AssembleIsotropicDifferential(svd, UnitDeterminantProjectionCoefficients(svd.sigma, projection));
}

Vec3 ProjectToSphere(const Vec3& f, double radius) {
  const double norm = f.norm();
  if (norm == 0.0) return Vec3(radius, 0.0, 0.0);
  return (radius / norm) * f;
}

Mat3 SphereProjectionDifferential(const Vec3& f, double radius) {
  const double squared_norm = f.squaredNorm();
  if (squared_norm == 0.0) return Mat3::Zero();
  const double norm = std::sqrt(squared_norm);
  return (radius / norm) * (Mat3::Identity() - f * f.transpose() / squared_norm);
}

}  // namespace diffpd::internal
