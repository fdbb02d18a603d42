// Differentials of isotropic matrix functions P(F) = U diag(p(sigma)) V^T
// (internal), where F = U diag(sigma) V^T is the signed SVD of Svd3.
//
// With M = U^T dF V (so d sigma_i = M_ii), the variation in the U, V frame is
//   (U^T dP V)_ii = sum_j (dp_i / dsigma_j) M_jj,
//   (U^T dP V)_ij = c^sym_ij (M_ij + M_ji) / 2 + c^skew_ij (M_ij - M_ji) / 2,  i != j,
//   c^sym_ij  = (p_i - p_j) / (sigma_i - sigma_j),
//   c^skew_ij = (p_i + p_j) / (sigma_i + sigma_j).
// In the orthonormal basis of R^9 made of vec(u_i v_i^T) and
// vec(u_i v_j^T +- u_j v_i^T) / sqrt(2), i < j, dP/dF is block diagonal: the
// 3x3 block dp/dsigma, then c^sym and c^skew per pair. Every projection and
// every SVD-based stress of the material area is assembled this way.
#pragma once

#include "diffpd/types.h"
#include "material/svd3.h"

namespace diffpd::internal {

// Pairs (i, j) in the order used by the coefficient vectors: (0,1), (0,2), (1,2).
inline constexpr int kPairFirst[3] = {0, 0, 1};
inline constexpr int kPairSecond[3] = {1, 2, 2};

struct IsotropicDifferentialCoefficients {
  Mat3 dp_dsigma = Mat3::Zero();  // (i, j) = dp_i / dsigma_j
  Vec3 symmetric = Vec3::Zero();  // c^sym per pair
  Vec3 skew = Vec3::Zero();       // c^skew per pair

  // Differentials in the same U, V frame add coefficient by coefficient.
  IsotropicDifferentialCoefficients& operator+=(const IsotropicDifferentialCoefficients& other) {
    dp_dsigma += other.dp_dsigma;
    symmetric += other.symmetric;
    skew += other.skew;
    return *this;
  }
};

// dP/dF (9x9, column-major flattening, see types.h) from the coefficients.
// Blocks whose coefficients are all zero are skipped (cost ~3 9x3x9 products).
Mat9 AssembleIsotropicDifferential(const Svd3& svd, const IsotropicDifferentialCoefficients& c);

// Relative floor of the denominators sigma_i + sigma_j (see DenominatorFloor).
inline constexpr double kProjectionDenominatorFloor = 1e-10;

// Relative tolerance below which sigma_i and sigma_j count as repeated.
inline constexpr double kRepeatedSingularValueTolerance = 1e-6;

// Floor for the denominators sigma_i + sigma_j (>= 0 for a signed SVD):
// kProjectionDenominatorFloor * max(sigma_0, 1) (dimensionless, like F).
double DenominatorFloor(const Vec3& sigma);

// The divided-difference coefficients of p, for p a symmetric function of
// sigma (p_i(sigma) = p_j(sigma) whenever sigma_i = sigma_j):
//  - c^sym: (p_i - p_j) / (sigma_i - sigma_j); when
//    sigma_i - sigma_j <= kRepeatedSingularValueTolerance max(|sigma_i|, |sigma_j|),
//    the symmetrised limit
//    (dp_i/dsigma_i - dp_i/dsigma_j + dp_j/dsigma_j - dp_j/dsigma_i) / 2,
//    accurate to O((sigma_i - sigma_j)^2) relative;
//  - c^skew: (p_i + p_j) / max(sigma_i + sigma_j, DenominatorFloor(sigma)).
IsotropicDifferentialCoefficients DividedDifferenceCoefficients(const Vec3& sigma, const Vec3& p,
                                                                const Mat3& dp_dsigma);

}  // namespace diffpd::internal
