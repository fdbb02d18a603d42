#include "material/isotropic_differential.h"

#include <algorithm>
#include <cmath>

namespace diffpd::internal {
namespace {

using Mat93 = Eigen::Matrix<double, 9, 3>;

// vec(a b^T) (column-major): entry r + 3 c = a(r) b(c).
inline Vec9 VecOuter(const Vec3& a, const Vec3& b) {
  Vec9 out;
  for (int c = 0; c < 3; ++c) out.segment<3>(3 * c) = a * b(c);
  return out;
}

}  // namespace

Mat9 AssembleIsotropicDifferential(const Svd3& svd, const IsotropicDifferentialCoefficients& c) {
  // Sum over the three blocks of (modes) (coefficients) (modes)^T.
  const Mat3& U = svd.U;
  const Mat3& V = svd.V;
  Mat9 result = Mat9::Zero();
  if (!c.dp_dsigma.isZero(0.0)) {
    Mat93 diagonal;
    for (int i = 0; i < 3; ++i) diagonal.col(i) = VecOuter(U.col(i), V.col(i));
    // lazyProduct: coefficient-based (9 + 9 + 3 is above Eigen's threshold for
    // fixed sizes, whose general product packs and blocks for 243 multiply-adds).
    result.noalias() += (diagonal * c.dp_dsigma).lazyProduct(diagonal.transpose());
  }
  const double inv_sqrt2 = 1.0 / std::sqrt(2.0);
  for (int sign = 0; sign < 2; ++sign) {
    const Vec3& coefficient = sign == 0 ? c.symmetric : c.skew;
    if (coefficient.isZero(0.0)) continue;
    Mat93 modes;
    for (int k = 0; k < 3; ++k) {
      const int i = kPairFirst[k], j = kPairSecond[k];
      const Vec9 ij = VecOuter(U.col(i), V.col(j));
      const Vec9 ji = VecOuter(U.col(j), V.col(i));
      modes.col(k) = (ij + (sign == 0 ? 1.0 : -1.0) * ji) * inv_sqrt2;
    }
    result.noalias() += (modes * coefficient.asDiagonal()).lazyProduct(modes.transpose());
  }
  return result;
}

double DenominatorFloor(const Vec3& sigma) { return kProjectionDenominatorFloor * std::max(sigma(0), 1.0); }

IsotropicDifferentialCoefficients DividedDifferenceCoefficients(const Vec3& sigma, const Vec3& p,
                                                                const Mat3& dp_dsigma) {
  IsotropicDifferentialCoefficients c;
  c.dp_dsigma = dp_dsigma;
  const double floor = DenominatorFloor(sigma);
  for (int k = 0; k < 3; ++k) {
    const int i = kPairFirst[k], j = kPairSecond[k];
    // sigma_i >= sigma_j for i < j in a signed SVD.
    const double difference = sigma(i) - sigma(j);
    const double threshold = kRepeatedSingularValueTolerance * std::max(std::abs(sigma(i)), std::abs(sigma(j)));
    if (difference > threshold) {
      c.symmetric(k) = (p(i) - p(j)) / difference;
    } else {
      c.symmetric(k) = 0.5 * (dp_dsigma(i, i) - dp_dsigma(i, j) + dp_dsigma(j, j) - dp_dsigma(j, i));
    }
    c.skew(k) = (p(i) + p(j)) / std::max(sigma(i) + sigma(j), floor);
  }
  return c;
}

}  // namespace diffpd::internal
