#include "fem/packed_element_matrices.h"

#include <cmath>

#include "material/simd_dispatch.h"

namespace diffpd::internal {
namespace {

// AddPackedSampleStiffness for K nodes per element, in structure-of-arrays
// form: every innermost loop runs over the lanes (one vector operation).
template <int K>
DIFFPD_SIMD_INLINE void AddPackedSampleStiffnessK(const PackedSampleLanes& s, double* packed) {
  constexpr int L = kElementLanes;
  const double inv_sqrt2 = 1.0 / std::sqrt(2.0);
  // dP/dF (9 x 9, (r, c) at r + 9 c) = sum over the modes of the U, V frame:
  // the diagonal modes vec(u_i v_i^T) with dp/dsigma, and per pair the
  // symmetric and skew modes (vec(u_i v_j^T) +- vec(u_j v_i^T)) / sqrt(2).
  alignas(64) double diag[3][9][L];
  for (int i = 0; i < 3; ++i)
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
#pragma omp simd
        for (int l = 0; l < L; ++l) diag[i][r + 3 * c][l] = s.u[r + 3 * i][l] * s.v[c + 3 * i][l];
  alignas(64) double dp[81][L];
  for (int r = 0; r < 9; ++r) {
    alignas(64) double m[3][L];  // row r of (diagonal modes) * dp/dsigma
    for (int j = 0; j < 3; ++j)
#pragma omp simd
      for (int l = 0; l < L; ++l)
        m[j][l] = diag[0][r][l] * s.dp_dsigma[3 * j][l] + diag[1][r][l] * s.dp_dsigma[1 + 3 * j][l] +
                  diag[2][r][l] * s.dp_dsigma[2 + 3 * j][l];
    for (int c = 0; c < 9; ++c)
#pragma omp simd
      for (int l = 0; l < L; ++l)
        dp[r + 9 * c][l] = m[0][l] * diag[0][c][l] + m[1][l] * diag[1][c][l] + m[2][l] * diag[2][c][l];
  }
  constexpr int first[3] = {0, 0, 1}, second[3] = {1, 2, 2};
  for (int k = 0; k < 3; ++k) {
    const int i = first[k], j = second[k];
    alignas(64) double sym[9][L], skw[9][L], csym[9][L], cskw[9][L];
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
#pragma omp simd
        for (int l = 0; l < L; ++l) {
          const double ij = s.u[r + 3 * i][l] * s.v[c + 3 * j][l], ji = s.u[r + 3 * j][l] * s.v[c + 3 * i][l];
          sym[r + 3 * c][l] = (ij + ji) * inv_sqrt2;
          skw[r + 3 * c][l] = (ij - ji) * inv_sqrt2;
          csym[r + 3 * c][l] = s.symmetric[k][l] * sym[r + 3 * c][l];
          cskw[r + 3 * c][l] = s.skew[k][l] * skw[r + 3 * c][l];
        }
    for (int c = 0; c < 9; ++c)
      for (int r = 0; r < 9; ++r)
#pragma omp simd
        for (int l = 0; l < L; ++l) dp[r + 9 * c][l] += csym[c][l] * sym[r][l] + cskw[c][l] * skw[r][l];
  }
  // Node column b: t(r, k) = vol sum_c dP(r, k + 3 c) G(b, c), then block
  // (a, b) += sum_j G(a, j) t(3 j + i, k) for a <= b (packed order).
  double* p = packed;
  for (int b = 0; b < K; ++b) {
    alignas(64) double t[27][L];
    for (int k = 0; k < 3; ++k)
      for (int r = 0; r < 9; ++r)
#pragma omp simd
        for (int l = 0; l < L; ++l) {
          const double vol = s.volume[l];
          t[r + 9 * k][l] = vol * (s.grad[b][l] * dp[r + 9 * k][l] + s.grad[b + K][l] * dp[r + 9 * (k + 3)][l] +
                                   s.grad[b + 2 * K][l] * dp[r + 9 * (k + 6)][l]);
        }
    for (int a = 0; a <= b; ++a, p += 9 * L)
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i)
#pragma omp simd
          for (int l = 0; l < L; ++l)
            p[(i + 3 * k) * L + l] += s.grad[a][l] * t[i + 9 * k][l] + s.grad[a + K][l] * t[3 + i + 9 * k][l] +
                                      s.grad[a + 2 * K][l] * t[6 + i + 9 * k][l];
  }
}

}  // namespace

DIFFPD_SIMD_CLONES
void AddPackedSampleStiffness(int nodes_per_element, const PackedSampleLanes& sample, double* packed_group) {
  if (nodes_per_element == 4)
    AddPackedSampleStiffnessK<4>(sample, packed_group);
  else
    AddPackedSampleStiffnessK<8>(sample, packed_group);
}

// One clone per vector width (simd_dispatch.h); every loop over lanes is a
// vector operation.
DIFFPD_SIMD_CLONES
void ApplyPackedGroup(int nodes_per_element, const double* packed, const double (*z)[kElementLanes],
                      double (*y)[kElementLanes]) {
  const int rows = 3 * nodes_per_element;
  for (int r = 0; r < rows; ++r)
#pragma omp simd
    for (int l = 0; l < kElementLanes; ++l) y[r][l] = 0.0;
  const double* p = packed;
  for (int b = 0; b < nodes_per_element; ++b) {
    // Block (a, b), entry (i, k) at p[(i + 3 k) * lanes]: acts on node b's
    // entries and, transposed (symmetry), on node a's.
    for (int a = 0; a < b; ++a, p += 9 * kElementLanes) {
#pragma omp simd
      for (int l = 0; l < kElementLanes; ++l) {
        double block[9];
        for (int t = 0; t < 9; ++t) block[t] = p[t * kElementLanes + l];
        for (int i = 0; i < 3; ++i)
          y[3 * a + i][l] += block[i] * z[3 * b][l] + block[i + 3] * z[3 * b + 1][l] + block[i + 6] * z[3 * b + 2][l];
        for (int k = 0; k < 3; ++k)
          y[3 * b + k][l] +=
              block[3 * k] * z[3 * a][l] + block[3 * k + 1] * z[3 * a + 1][l] + block[3 * k + 2] * z[3 * a + 2][l];
      }
    }
#pragma omp simd
    for (int l = 0; l < kElementLanes; ++l) {  // the diagonal block (b, b)
      double block[9];
      for (int t = 0; t < 9; ++t) block[t] = p[t * kElementLanes + l];
      for (int i = 0; i < 3; ++i)
        y[3 * b + i][l] += block[i] * z[3 * b][l] + block[i + 3] * z[3 * b + 1][l] + block[i + 6] * z[3 * b + 2][l];
    }
    p += 9 * kElementLanes;
  }
}

}  // namespace diffpd::internal
