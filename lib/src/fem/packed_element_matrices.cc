#include "fem/packed_element_matrices.h"

#include "material/simd_dispatch.h"

namespace diffpd::internal {

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
          y[3 * b + k][l] += block[3 * k] * z[3 * a][l] + block[3 * k + 1] * z[3 * a + 1][l] +
                             block[3 * k + 2] * z[3 * a + 2][l];
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
