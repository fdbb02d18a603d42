#include "fem/pd_hex_kernel.h"

#include <cmath>

#include "material/projections.h"
#include "material/simd_dispatch.h"
#include "material/svd3.h"

namespace diffpd::internal {
namespace {

constexpr int kLanes = 8;  // one hexahedron's samples fill an SVD batch
static_assert(kSvdBatch == kLanes && kVolumeBatch == kLanes, "one lane per hexahedron sample");

// F = xe G for every lane, the unscaled-path test, and the SVD input
// B = F v_guess with det B. Returns whether every lane is fit for the batch.
DIFFPD_SIMD_CLONES
bool PrepareLanes(const double* xe, const double* g, const Mat3* v_cache, Svd3Lanes& m) {
  alignas(64) double f[9][kLanes];
  alignas(64) double v[9][kLanes];
  for (int l = 0; l < kLanes; ++l) {
    const double* vl = v_cache[l].data();
    for (int k = 0; k < 9; ++k) v[k][l] = vl[k];
  }
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    for (int c = 0; c < 3; ++c) {
      for (int r = 0; r < 3; ++r) {
        double sum = 0.0;
        for (int a = 0; a < 8; ++a) sum += xe[r + 3 * a] * g[(a + 8 * c) * kLanes + l];
        f[r + 3 * c][l] = sum;
      }
    }
  }
  // probe: NaN when an entry is not finite; lane_max: each lane's max |F(i, j)|.
  double probe = 0.0;
  double lane_max[kLanes];
#pragma omp simd reduction(+ : probe)
  for (int l = 0; l < kLanes; ++l) {
    double max_abs = 0.0;
    for (int k = 0; k < 9; ++k) {
      const double magnitude = std::abs(f[k][l]);
      max_abs = magnitude > max_abs ? magnitude : max_abs;
      probe += 0.0 * f[k][l];
    }
    lane_max[l] = max_abs;
  }
  bool fit = probe == 0.0;
  for (int l = 0; l < kLanes; ++l) fit = fit && lane_max[l] >= 1e-100 && lane_max[l] <= 1e100;
  if (!fit) return false;
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        m.b[r + 3 * c][l] = f[r][l] * v[3 * c][l] + f[r + 3][l] * v[1 + 3 * c][l] + f[r + 6][l] * v[2 + 3 * c][l];
    for (int k = 0; k < 9; ++k) m.v[k][l] = v[k][l];
    const double b00 = m.b[0][l], b10 = m.b[1][l], b20 = m.b[2][l];
    const double b01 = m.b[3][l], b11 = m.b[4][l], b21 = m.b[5][l];
    const double b02 = m.b[6][l], b12 = m.b[7][l], b22 = m.b[8][l];
    m.det_sign_reference[l] =
        b00 * (b11 * b22 - b21 * b12) - b01 * (b10 * b22 - b20 * b12) + b02 * (b10 * b21 - b20 * b11);
  }
  return true;
}

// Stresses, energy and nodal forces from the decomposed lanes; d = projected
// singular values (sigma itself when w_vol = 0). Writes V back to v_cache.
DIFFPD_SIMD_CLONES
void LaneForces(const Svd3Lanes& m, const double (*d)[kLanes], const double* grads, const double* sample_volume,
                double w_rot, double w_vol, Mat3* v_cache, double* fe, double* energy) {
  alignas(64) double p[9][kLanes];  // vol * P, entry r + 3 c
  double total = 0.0;
#pragma omp simd reduction(+ : total)
  for (int l = 0; l < kLanes; ++l) {
    double diag[3];
    double psi = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double s = m.sigma[i][l];
      const double stretch = s - 1.0;
      const double excess = s - d[i][l];
      psi += w_rot * stretch * stretch + w_vol * excess * excess;
      diag[i] = sample_volume[l] * (w_rot * stretch + w_vol * excess);
    }
    total += 0.5 * sample_volume[l] * psi;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        p[r + 3 * c][l] = m.u[r][l] * diag[0] * m.v[c][l] + m.u[r + 3][l] * diag[1] * m.v[c + 3][l] +
                          m.u[r + 6][l] * diag[2] * m.v[c + 6][l];
  }
  *energy = total;
  // fe(r, a) = sum_l sum_c vol P_l(r, c) G_l(a, c), vectorised over the nodes a
  // (each sample's 8 x 3 gradients are column-major: G_l(., c) is contiguous).
  alignas(64) double rows[3][8] = {};
  for (int l = 0; l < kLanes; ++l) {
    for (int c = 0; c < 3; ++c) {
      const double* column = grads + 24 * l + 8 * c;
      for (int r = 0; r < 3; ++r) {
        const double weight = p[r + 3 * c][l];
#pragma omp simd
        for (int a = 0; a < 8; ++a) rows[r][a] += weight * column[a];
      }
    }
  }
  for (int a = 0; a < 8; ++a)
    for (int r = 0; r < 3; ++r) fe[r + 3 * a] = rows[r][a];
  for (int l = 0; l < kLanes; ++l) {
    double* vl = v_cache[l].data();
    for (int k = 0; k < 9; ++k) vl[k] = m.v[k][l];
  }
}

}  // namespace

bool PdHexEnergyAndForces(const double* xe, const double* g, const double* grads, const double* sample_volume,
                          const PdHexWeights& w, Mat3* v_cache, double* fe, double* energy) {
  Svd3Lanes m;
  if (!PrepareLanes(xe, g, v_cache, m)) return false;
  ComputeSvd3Lanes(m);
  VolumeLanes b;
  if (w.volume != 0.0) {
    bool lane_applies[kLanes];
    for (int l = 0; l < kLanes; ++l) {
      lane_applies[l] = VolumeLanesApply(Vec3(m.sigma[0][l], m.sigma[1][l], m.sigma[2][l]));
      for (int i = 0; i < 3; ++i) {
        b.s[i][l] = lane_applies[l] ? m.sigma[i][l] : 1.0;
        b.d[i][l] = 1.0;
      }
    }
    ProjectVolumeLanes(b);
    for (int l = 0; l < kLanes; ++l) {
      if (lane_applies[l] && b.done[l] != 0.0) continue;
      const VolumeProjection single =
          ProjectSingularValuesToUnitDeterminant(Vec3(m.sigma[0][l], m.sigma[1][l], m.sigma[2][l]));
      for (int i = 0; i < 3; ++i) b.d[i][l] = single.d(i);
    }
  }
  LaneForces(m, w.volume != 0.0 ? b.d : m.sigma, grads, sample_volume, w.rotation, w.volume, v_cache, fe, energy);
  return true;
}

}  // namespace diffpd::internal
