// Signed 3x3 SVD by one-sided (Hestenes) Jacobi followed by a Givens QR.
//
// Method (McAdams et al. 2011, "Computing the singular value decomposition of
// 3x3 matrices with minimal branching and elementary floating point
// operations", with exact instead of approximate Jacobi rotations):
//  1. B = F V: cyclic sweeps of plane rotations applied to the columns of B
//     (and accumulated in V) until every pair of columns is orthogonal to
//     working precision, |b_p . b_q| <= eps |b_p| |b_q|. This is Jacobi on
//     F^T F without ever forming F^T F, so small singular values keep their
//     accuracy relative to |F| (no squaring of the condition number).
//  2. Sort the columns by decreasing norm; flip the last column of B and V if
//     needed so that det V = +1.
//  3. B = U R by three Givens rotations: U is a product of rotations (hence
//     orthogonal with det +1 to rounding, even when B has zero columns), R is
//     upper triangular with R00, R11 >= 0 and diagonal |b_i| up to the sign
//     of R22, which carries the sign of det F. R's off-diagonal entries are
//     O(eps |F|) because B's columns are orthogonal, so sigma = diag(R).
//
// Why not Eigen::JacobiSVD<Matrix3d> (two-sided Jacobi): measured at -O3 over
// 2e5 random matrices (entries uniform in [-1, 1], and I + 0.1 * that) on the
// development machine (a shared 2-core AMD EPYC, so absolute numbers are
// noisy): ~0.36 us per call here vs ~0.70 us for JacobiSVD with full U and V;
// worst relative reconstruction error 1.7e-15 vs 3.6e-15 and worst
// orthogonality error |U^T U - I|_F 3.0e-15 vs 3.4e-15. JacobiSVD also returns
// unsigned singular values and possibly improper U, V, which would need a
// further sign fix-up. Random matrices take 3 or 4 sweeps (rarely 2 or 5)
// plus one sweep that finds nothing left to rotate.
#include "material/svd3.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/LU>

#include "diffpd/error.h"
#include "material/simd_dispatch.h"

namespace diffpd::internal {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
// Each sweep is 3 rotations; convergence is quadratic (see above).
constexpr int kMaxSweeps = 20;

// Rotates columns i and j of B (and V) so that they become orthogonal.
// Returns false (and does nothing) when they already are to working precision.
inline bool OrthogonalizeColumns(Mat3& B, Mat3& V, int i, int j) {
  const double alpha = B.col(i).squaredNorm();
  const double beta = B.col(j).squaredNorm();
  const double gamma = B.col(i).dot(B.col(j));
  if (!(gamma * gamma > kEps * kEps * alpha * beta)) return false;
  // Rutishauser's rotation: t = tan(theta), the root of smaller magnitude of
  // t^2 + 2 zeta t - 1 = 0, zeta = (beta - alpha) / (2 gamma), diagonalises
  // [[alpha, gamma], [gamma, beta]]. With root = sqrt(diff^2 + 4 gamma^2) and
  // q = |diff| + root, t = 2 gamma sign(diff) / q and 1 + t^2 = 2 root / q, so
  //   c = q / sqrt(2 q root),  s = 2 gamma sign(diff) / sqrt(2 q root)
  // (two square roots and one division).
  const double diff = beta - alpha;
  const double root = std::sqrt(diff * diff + 4.0 * gamma * gamma);
  const double q = std::abs(diff) + root;
  const double w = 1.0 / std::sqrt(2.0 * q * root);
  const double c = q * w;
  const double s = (diff >= 0.0 ? 2.0 : -2.0) * gamma * w;
  for (int r = 0; r < 3; ++r) {
    const double bi = B(r, i), bj = B(r, j);
    B(r, i) = c * bi - s * bj;
    B(r, j) = s * bi + c * bj;
    const double vi = V(r, i), vj = V(r, j);
    V(r, i) = c * vi - s * vj;
    V(r, j) = s * vi + c * vj;
  }
  return true;
}

// Givens rotation on rows (p, q) of B zeroing B(q, col) with B(p, col) >= 0;
// accumulates U <- U G^T so that U B stays constant.
inline void GivensZero(Mat3& B, Mat3& U, int p, int q, int col) {
  const double a = B(p, col), b = B(q, col);
  const double r = std::sqrt(a * a + b * b);
  if (r == 0.0) return;
  const double c = a / r, s = b / r;
  for (int j = 0; j < 3; ++j) {
    const double bp = B(p, j), bq = B(q, j);
    B(p, j) = c * bp + s * bq;
    B(q, j) = -s * bp + c * bq;
    const double up = U(j, p), uq = U(j, q);
    U(j, p) = c * up + s * uq;
    U(j, q) = -s * up + c * uq;
  }
  B(p, col) = r;
  B(q, col) = 0.0;
}

inline void SwapColumns(Mat3& B, Mat3& V, Vec3& norms, int i, int j) {
  B.col(i).swap(B.col(j));
  V.col(i).swap(V.col(j));
  std::swap(norms(i), norms(j));
}

// Steps 2 and 3 on B = F V with orthogonal columns (V accumulated in svd->V);
// det_sign_reference is det(F v_guess) (its sign is det F's), exponent the
// power of two F was scaled by.
void FinishSvd(Mat3 B, double det_sign_reference, int exponent, Svd3* svd) {
  Mat3& V = svd->V;
  Vec3 norms = B.colwise().squaredNorm().transpose();
  bool odd = false;
  if (norms(0) < norms(1)) {
    SwapColumns(B, V, norms, 0, 1);
    odd = !odd;
  }
  if (norms(0) < norms(2)) {
    SwapColumns(B, V, norms, 0, 2);
    odd = !odd;
  }
  if (norms(1) < norms(2)) {
    SwapColumns(B, V, norms, 1, 2);
    odd = !odd;
  }
  if (odd) {
    B.col(2) = -B.col(2);
    V.col(2) = -V.col(2);
  }

  Mat3& U = svd->U;
  U.setIdentity();
  GivensZero(B, U, 0, 1, 0);
  GivensZero(B, U, 0, 2, 0);
  GivensZero(B, U, 1, 2, 1);

  Vec3& sigma = svd->sigma;
  sigma << B(0, 0), B(1, 1), B(2, 2);
  // Rounding can leave (nearly) repeated values out of order by an ulp.
  sigma(1) = std::min(sigma(1), sigma(0));
  if (std::abs(sigma(2)) > sigma(1)) sigma(2) = std::copysign(sigma(1), sigma(2));
  // When det F is at round-off level its computed sign and R22's may
  // disagree; R22 is then itself at round-off level and flipping it costs
  // O(eps |F|) in the reconstruction while keeping sign(sigma2) = sign(det F).
  const bool negative = sigma(2) < 0.0;
  if (negative != (det_sign_reference < 0.0) && std::abs(sigma(2)) <= 8.0 * kEps * sigma(0)) {
    sigma(2) = -sigma(2);
  }
  if (exponent != 0) sigma *= std::ldexp(1.0, exponent);
}

// True when F can take the unscaled path: finite, nonzero, entries within
// [1e-100, 1e100] in magnitude (no rescaling needed).
inline bool NeedsNoRescaling(const Mat3& F) {
  if (!F.allFinite()) return false;
  const double max_abs = F.cwiseAbs().maxCoeff();
  return max_abs != 0.0 && max_abs >= 1e-100 && max_abs <= 1e100;
}

// Structure-of-arrays Jacobi sweeps over kSvdBatch matrices (Svd3Lanes). The
// same rotations as OrthogonalizeColumns, lane by lane; a lane whose columns
// are already orthogonal gets c = 1, s = 0, which leaves it unchanged exactly,
// so every lane ends as its own scalar sweep would.
DIFFPD_SIMD_INLINE bool OrthogonalizeLanePair(Svd3Lanes& m, int i, int j) {
  int any = 0;
  const double eps2 = kEps * kEps;
  // The test first, over all lanes: the last sweep of a converged batch
  // rotates no lane and skips the rotation arithmetic below.
  double alphas[kSvdBatch], betas[kSvdBatch], gammas[kSvdBatch];
#pragma omp simd reduction(| : any)
  for (int l = 0; l < kSvdBatch; ++l) {
    const double bi0 = m.b[3 * i][l], bi1 = m.b[3 * i + 1][l], bi2 = m.b[3 * i + 2][l];
    const double bj0 = m.b[3 * j][l], bj1 = m.b[3 * j + 1][l], bj2 = m.b[3 * j + 2][l];
    alphas[l] = bi0 * bi0 + bi1 * bi1 + bi2 * bi2;
    betas[l] = bj0 * bj0 + bj1 * bj1 + bj2 * bj2;
    gammas[l] = bi0 * bj0 + bi1 * bj1 + bi2 * bj2;
    any |= gammas[l] * gammas[l] > eps2 * alphas[l] * betas[l] ? 1 : 0;
  }
  if (any == 0) return false;
#pragma omp simd
  for (int l = 0; l < kSvdBatch; ++l) {
    const double bi0 = m.b[3 * i][l], bi1 = m.b[3 * i + 1][l], bi2 = m.b[3 * i + 2][l];
    const double bj0 = m.b[3 * j][l], bj1 = m.b[3 * j + 1][l], bj2 = m.b[3 * j + 2][l];
    const double alpha = alphas[l], beta = betas[l], gamma = gammas[l];
    const bool rotate = gamma * gamma > eps2 * alpha * beta;
    const double diff = beta - alpha;
    const double root = std::sqrt(diff * diff + 4.0 * gamma * gamma);
    const double q = std::abs(diff) + root;
    // Computed in every lane (no branch; inf or NaN where nothing rotates,
    // discarded by the selects).
    const double w = 1.0 / std::sqrt(2.0 * q * root);
    const double signed_two = diff >= 0.0 ? 2.0 : -2.0;
    const double c = rotate ? q * w : 1.0;
    const double s = rotate ? signed_two * gamma * w : 0.0;
    m.b[3 * i][l] = c * bi0 - s * bj0;
    m.b[3 * i + 1][l] = c * bi1 - s * bj1;
    m.b[3 * i + 2][l] = c * bi2 - s * bj2;
    m.b[3 * j][l] = s * bi0 + c * bj0;
    m.b[3 * j + 1][l] = s * bi1 + c * bj1;
    m.b[3 * j + 2][l] = s * bi2 + c * bj2;
    const double vi0 = m.v[3 * i][l], vi1 = m.v[3 * i + 1][l], vi2 = m.v[3 * i + 2][l];
    const double vj0 = m.v[3 * j][l], vj1 = m.v[3 * j + 1][l], vj2 = m.v[3 * j + 2][l];
    m.v[3 * i][l] = c * vi0 - s * vj0;
    m.v[3 * i + 1][l] = c * vi1 - s * vj1;
    m.v[3 * i + 2][l] = c * vi2 - s * vj2;
    m.v[3 * j][l] = s * vi0 + c * vj0;
    m.v[3 * j + 1][l] = s * vi1 + c * vj1;
    m.v[3 * j + 2][l] = s * vi2 + c * vj2;
  }
  return true;
}

// Swaps columns i and j of B and V (and their squared norms) in the lanes
// where norm_i < norm_j, flipping those lanes' permutation parity.
DIFFPD_SIMD_INLINE void BatchSortPair(Svd3Lanes& m, double (&norms)[3][kSvdBatch], double* odd, int i, int j) {
#pragma omp simd
  for (int l = 0; l < kSvdBatch; ++l) {
    const bool swap = norms[i][l] < norms[j][l];
    for (int r = 0; r < 3; ++r) {
      const double bi = m.b[3 * i + r][l], bj = m.b[3 * j + r][l];
      m.b[3 * i + r][l] = swap ? bj : bi;
      m.b[3 * j + r][l] = swap ? bi : bj;
      const double vi = m.v[3 * i + r][l], vj = m.v[3 * j + r][l];
      m.v[3 * i + r][l] = swap ? vj : vi;
      m.v[3 * j + r][l] = swap ? vi : vj;
    }
    const double ni = norms[i][l], nj = norms[j][l];
    norms[i][l] = swap ? nj : ni;
    norms[j][l] = swap ? ni : nj;
    odd[l] = swap ? -odd[l] : odd[l];
  }
}

// GivensZero lane by lane (rows p, q of B, zeroing B(q, col)); lanes with
// a = b = 0 get c = 1, s = 0, i.e. no change, as the scalar code skips them.
DIFFPD_SIMD_INLINE void BatchGivens(Svd3Lanes& m, int p, int q, int col) {
#pragma omp simd
  for (int l = 0; l < kSvdBatch; ++l) {
    const double a = m.b[p + 3 * col][l], b = m.b[q + 3 * col][l];
    const double r = std::sqrt(a * a + b * b);
    const bool skip = r == 0.0;
    const double inv = 1.0 / r;
    const double c = skip ? 1.0 : a * inv, s = skip ? 0.0 : b * inv;
    for (int j = 0; j < 3; ++j) {
      const double bp = m.b[p + 3 * j][l], bq = m.b[q + 3 * j][l];
      m.b[p + 3 * j][l] = c * bp + s * bq;
      m.b[q + 3 * j][l] = -s * bp + c * bq;
      const double up = m.u[j + 3 * p][l], uq = m.u[j + 3 * q][l];
      m.u[j + 3 * p][l] = c * up + s * uq;
      m.u[j + 3 * q][l] = -s * up + c * uq;
    }
    m.b[p + 3 * col][l] = skip ? a : r;
    m.b[q + 3 * col][l] = skip ? b : 0.0;
  }
}

// FinishSvd (steps 2 and 3) lane by lane, the same operations with selects
// for branches; lanes are unscaled (exponent 0).
DIFFPD_SIMD_INLINE void BatchFinish(Svd3Lanes& m) {
  double norms[3][kSvdBatch];
  double odd[kSvdBatch];
#pragma omp simd
  for (int l = 0; l < kSvdBatch; ++l) {
    for (int c = 0; c < 3; ++c) {
      const double x = m.b[3 * c][l], y = m.b[3 * c + 1][l], z = m.b[3 * c + 2][l];
      norms[c][l] = x * x + y * y + z * z;
    }
    odd[l] = 1.0;
  }
  BatchSortPair(m, norms, odd, 0, 1);
  BatchSortPair(m, norms, odd, 0, 2);
  BatchSortPair(m, norms, odd, 1, 2);
#pragma omp simd
  for (int l = 0; l < kSvdBatch; ++l) {
    for (int r = 0; r < 3; ++r) {
      m.b[6 + r][l] *= odd[l];
      m.v[6 + r][l] *= odd[l];
    }
    for (int k = 0; k < 9; ++k) m.u[k][l] = k % 4 == 0 ? 1.0 : 0.0;
  }
  BatchGivens(m, 0, 1, 0);
  BatchGivens(m, 0, 2, 0);
  BatchGivens(m, 1, 2, 1);
#pragma omp simd
  for (int l = 0; l < kSvdBatch; ++l) {
    const double s0 = m.b[0][l];
    const double s1 = std::min(m.b[4][l], s0);
    double s2 = m.b[8][l];
    s2 = std::abs(s2) > s1 ? std::copysign(s1, s2) : s2;
    const bool flip = (s2 < 0.0) != (m.det_sign_reference[l] < 0.0) && std::abs(s2) <= 8.0 * kEps * s0;
    m.sigma[0][l] = s0;
    m.sigma[1][l] = s1;
    m.sigma[2][l] = flip ? -s2 : s2;
  }
}

}  // namespace

// The batch's sweeps and finish, one clone per vector width (simd_dispatch.h).
DIFFPD_SIMD_CLONES
void ComputeSvd3Lanes(Svd3Lanes& m) {
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    bool rotated = OrthogonalizeLanePair(m, 0, 1);
    rotated = OrthogonalizeLanePair(m, 0, 2) || rotated;
    rotated = OrthogonalizeLanePair(m, 1, 2) || rotated;
    if (!rotated) break;
  }
  BatchFinish(m);
}

Svd3 ComputeSvd3(const Mat3& F) { return ComputeSvd3(F, Mat3::Identity()); }

Svd3 ComputeSvd3(const Mat3& F, const Mat3& v_guess) {
  Svd3 svd;
  svd.U.setIdentity();
  svd.V = v_guess;
  if (!F.allFinite()) {
    svd.sigma.setConstant(std::numeric_limits<double>::quiet_NaN());
    return svd;
  }
  const double max_abs = F.cwiseAbs().maxCoeff();
  if (max_abs == 0.0) {
    svd.sigma.setZero();
    return svd;
  }
  // Exact power-of-two rescaling keeps squared norms clear of under/overflow.
  int exponent = 0;
  Mat3 B = F * v_guess;
  if (max_abs < 1e-100 || max_abs > 1e100) {
    exponent = std::ilogb(max_abs);
    B *= std::ldexp(1.0, -exponent);
  }
  const double det_sign_reference = B.determinant();

  Mat3& V = svd.V;
  for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
    bool rotated = OrthogonalizeColumns(B, V, 0, 1);
    rotated = OrthogonalizeColumns(B, V, 0, 2) || rotated;
    rotated = OrthogonalizeColumns(B, V, 1, 2) || rotated;
    if (!rotated) break;
  }
  FinishSvd(B, det_sign_reference, exponent, &svd);
  return svd;
}

void ComputeSvd3Batch(int count, const Mat3* F, const Mat3* v_guess, Svd3* out) {
  DIFFPD_CHECK(count >= 0 && count <= kSvdBatch, "ComputeSvd3Batch: count = " << count);
  if (count <= 2) {  // too few lanes to pay for the batch
    for (int l = 0; l < count; ++l) out[l] = ComputeSvd3(F[l], v_guess[l]);
    return;
  }
  Svd3Lanes m;
  bool batched[kSvdBatch];
  for (int l = 0; l < kSvdBatch; ++l) {
    batched[l] = l < count && NeedsNoRescaling(F[l]);
    // Unused and special lanes hold the identity: orthogonal, never rotated.
    const Mat3 B = batched[l] ? Mat3(F[l] * v_guess[l]) : Mat3::Identity();
    const Mat3 V = batched[l] ? v_guess[l] : Mat3::Identity();
    m.det_sign_reference[l] = batched[l] ? B.determinant() : 1.0;
    for (int k = 0; k < 9; ++k) {
      m.b[k][l] = B(k);
      m.v[k][l] = V(k);
    }
  }
  ComputeSvd3Lanes(m);
  for (int l = 0; l < count; ++l) {
    if (!batched[l]) {
      out[l] = ComputeSvd3(F[l], v_guess[l]);
      continue;
    }
    for (int k = 0; k < 9; ++k) {
      out[l].U(k) = m.u[k][l];
      out[l].V(k) = m.v[k][l];
    }
    for (int i = 0; i < 3; ++i) out[l].sigma(i) = m.sigma[i][l];
  }
}

}  // namespace diffpd::internal
