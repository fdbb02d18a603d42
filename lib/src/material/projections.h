// Projections of a deformation gradient onto the constraint sets of the PD
// energies, and their differentials (internal). Each PD energy has the form
//   Psi(F) = (w/2) |F - Proj(F)|^2,
// so its stress is w (F - Proj(F)) and its stress differential is
// w (I - dProj/dF) (the projection being a minimiser, Proj's own variation
// drops out of the stress).
#pragma once

#include "diffpd/types.h"
#include "material/isotropic_differential.h"
#include "material/svd3.h"

namespace diffpd::internal {

// Closest rotation to F in the Frobenius norm: U V^T of the signed SVD.
Mat3 ProjectToRotation(const Svd3& svd);
// d vec(Proj) / d vec(F) (9x9, column-major flattening), well defined while
// sigma_i + sigma_j > 0 for all i != j; clamps the denominators otherwise.
Mat9 RotationProjectionDifferential(const Svd3& svd);

// Closest matrix of unit determinant to F: U diag(d) V^T, where d minimises
// |d - sigma|^2 subject to d0 d1 d2 = 1 (Lagrange conditions solved by a
// safeguarded Newton iteration on the multiplier).
struct VolumeProjection {
  Vec3 d;             // projected singular values
  double multiplier;  // Lagrange multiplier of the determinant constraint
};
VolumeProjection ProjectSingularValuesToUnitDeterminant(const Vec3& sigma);
// out[i] = ProjectSingularValuesToUnitDeterminant(sigma[i]) for i < count
// (<= kVolumeBatch), the common case (all sigma > 0, prod < 2) solved for all
// entries together lane by lane (OpenMP SIMD), the others one by one.
// Results match the single calls to rounding.
constexpr int kVolumeBatch = 16;
void ProjectSingularValuesToUnitDeterminantBatch(int count, const Vec3* sigma, VolumeProjection* out);
// The batch's common case in structure-of-arrays form. In: s[i][l] = sigma_i
// of lane l (any values). Out: for lanes in the common case (sigma_2 > 0,
// finite, prod(sigma) < 2) whose Halley iteration settled, done[l] = 1 and
// d[i][l], mu[l] (the multiplier) as ProjectSingularValuesToUnitDeterminant
// gives them up to rounding; done[l] = 0 for the other lanes, which need the
// single call.
struct alignas(64) VolumeLanes {
  double s[3][kVolumeBatch];
  double d[3][kVolumeBatch];
  double mu[kVolumeBatch];
  double done[kVolumeBatch];
};
void ProjectVolumeLanes(VolumeLanes& b);
Mat3 ProjectToUnitDeterminant(const Svd3& svd);
Mat9 UnitDeterminantProjectionDifferential(const Svd3& svd);

// d d / d sigma (3x3, (i, j) = dd_i / dsigma_j) of the singular-value
// projection, by implicit differentiation of its KKT system
//   d_i - sigma_i - mu / d_i = 0,  sum_i log|d_i| = 0.
Mat3 UnitDeterminantProjectionJacobian(const Vec3& sigma, const VolumeProjection& projection);
// The coefficients of dProj/dF (see isotropic_differential.h) for
// p = projection.d. Pairs whose entries sit on different solution branches
// (d_i, d_j of different signs, or one of them on the shrinking branch
// d < sigma/2), where p jumps as sigma_i and sigma_j cross, use the divided
// difference with a clamped denominator instead of the repeated-value limit.
IsotropicDifferentialCoefficients UnitDeterminantProjectionCoefficients(const Vec3& sigma,
                                                                        const VolumeProjection& projection);

// Implementation notes for the declarations above (projections.cc,
// volume_projection.cc):
//  - RotationProjectionDifferential: with M = U^T dF V, U^T dR V is
//    antisymmetric with entries (M_ij - M_ji) / (sigma_i + sigma_j); the sums
//    sigma_i + sigma_j (>= 0 by the signed-SVD ordering) are clamped below at
//    kProjectionDenominatorFloor * max(sigma_0, 1). They vanish only where the
//    rotation itself is discontinuous (rank <= 1, or sigma_1 = -sigma_2);
//    see DenominatorFloor in isotropic_differential.h.
//  - ProjectSingularValuesToUnitDeterminant returns the global minimiser for
//    any sigma (sigma_0 >= sigma_1 >= |sigma_2|): d_0 > 0 always; for
//    sigma_2 < 0 the minimiser may have d_1, d_2 < 0 (a rotation by pi away),
//    which is still a matrix of determinant +1. The constrained problem is not
//    convex: for a uniform expansion F = s I with s > ~1.905 the closest point
//    keeps two directions and crushes the last (s = 2: d = (1.618, 1.618,
//    0.382)), and the projection is discontinuous where two local minimisers
//    tie. The Newton iteration runs on t = d_k (smallest target entry), which
//    fixes the multiplier as mu = t (t - s_k); `multiplier` is mu with
//    d_i - sigma_i = mu / d_i (= mu prod(d) / d_i). Relative accuracy ~1e-15.
//    The common case sigma_2 > 0, prod(sigma) < 2 (a unique candidate) first
//    tries Halley's iteration on mu itself from the first-order guess (two
//    evaluations for typical strains, 40% of the general path's cost).
//  - UnitDeterminantProjectionDifferential: exact (implicit differentiation
//    of the KKT system and the SVD-derivative formulas; see
//    isotropic_differential.h), same denominator floor.

// Muscle fibre projection: the closest point to f on the sphere |p| = radius,
//   p = radius f / |f|   (f, p: 3-vectors, same units as radius).
// For f = 0 every point of the sphere is equally close; returns radius e_x.
Vec3 ProjectToSphere(const Vec3& f, double radius);
// d p / d f = radius (I - f f^T / |f|^2) / |f| (3x3, units radius / |f|).
// For f = 0, where the projection is discontinuous and has no derivative,
// returns the zero matrix.
Mat3 SphereProjectionDifferential(const Vec3& f, double radius);

}  // namespace diffpd::internal
