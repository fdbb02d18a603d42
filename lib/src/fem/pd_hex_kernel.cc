#include "fem/pd_hex_kernel.h"

#include <cmath>

#include "diffpd/error.h"
#include "material/projections.h"
#include "material/simd_dispatch.h"
#include "material/svd3.h"

namespace diffpd::internal {
namespace {

constexpr int kLanes = 8 * kPdHexBatch;  // element j's samples in lanes 8 j .. 8 j + 7
static_assert(kSvdBatch == kLanes && kVolumeBatch == kLanes, "one lane per sample of a batch of hexahedra");

// Per lane: the element's weights and the sample's volume (idle lanes: 0).
struct LaneWeights {
  alignas(64) double rotation[kLanes];
  alignas(64) double volume[kLanes];
  alignas(64) double sample_volume[kLanes];
};

// F = xe G for every lane of the `count` elements (idle lanes: F = I,
// V = I), the unscaled-path test, and the SVD input B = F v_guess with
// det B. Returns whether every lane is fit for the batch.
DIFFPD_SIMD_CLONES
bool PrepareLanes(const PdHexElement* elements, int count, Svd3Lanes& m) {
  alignas(64) double f[9][kLanes];
  alignas(64) double v[9][kLanes];
  for (int j = 0; j < kPdHexBatch; ++j) {
    const bool idle = j >= count;
    for (int q = 0; q < 8; ++q) {
      const int l = 8 * j + q;
      const double* vl = idle ? nullptr : elements[j].v_cache[q].data();
      for (int k = 0; k < 9; ++k) v[k][l] = idle ? (k % 4 == 0 ? 1.0 : 0.0) : vl[k];
    }
    if (idle) {
      for (int k = 0; k < 9; ++k)
        for (int q = 0; q < 8; ++q) f[k][8 * j + q] = k % 4 == 0 ? 1.0 : 0.0;
      continue;
    }
    const double* xe = elements[j].xe;
    const double* g = elements[j].lane_gradients;
#pragma omp simd
    for (int q = 0; q < 8; ++q) {
      for (int c = 0; c < 3; ++c) {
        for (int r = 0; r < 3; ++r) {
          double sum = 0.0;
          for (int a = 0; a < 8; ++a) sum += xe[r + 3 * a] * g[(a + 8 * c) * 8 + q];
          f[r + 3 * c][8 * j + q] = sum;
        }
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

// Stresses, energies and nodal forces of the `count` elements from the
// decomposed lanes; d = projected singular values (read only in lanes with a
// volume weight). Writes V back to the elements' caches.
DIFFPD_SIMD_CLONES
void LaneForces(const Svd3Lanes& m, const double (*d)[kLanes], const LaneWeights& w, const PdHexElement* elements,
                int count) {
  alignas(64) double p[9][kLanes];  // vol * P, entry r + 3 c
  alignas(64) double psi[kLanes];   // vol * Psi
#pragma omp simd
  for (int l = 0; l < kLanes; ++l) {
    double diag[3];
    double density = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double s = m.sigma[i][l];
      const double stretch = s - 1.0;
      const double excess = w.volume[l] != 0.0 ? s - d[i][l] : 0.0;
      density += w.rotation[l] * stretch * stretch + w.volume[l] * excess * excess;
      diag[i] = w.sample_volume[l] * (w.rotation[l] * stretch + w.volume[l] * excess);
    }
    psi[l] = 0.5 * w.sample_volume[l] * density;
    for (int c = 0; c < 3; ++c)
      for (int r = 0; r < 3; ++r)
        p[r + 3 * c][l] = m.u[r][l] * diag[0] * m.v[c][l] + m.u[r + 3][l] * diag[1] * m.v[c + 3][l] +
                          m.u[r + 6][l] * diag[2] * m.v[c + 6][l];
  }
  for (int j = 0; j < count; ++j) {
    const PdHexElement& element = elements[j];
    double energy = 0.0;
    for (int q = 0; q < 8; ++q) energy += psi[8 * j + q];
    *element.energy = energy;
    // fe(r, a) = sum_q sum_c vol P_q(r, c) G_q(a, c), vectorised over the
    // nodes a (each sample's 8 x 3 gradients are column-major: G_q(., c) is
    // contiguous).
    alignas(64) double rows[3][8] = {};
    for (int q = 0; q < 8; ++q) {
      for (int c = 0; c < 3; ++c) {
        const double* column = element.grads + 24 * q + 8 * c;
        for (int r = 0; r < 3; ++r) {
          const double weight = p[r + 3 * c][8 * j + q];
#pragma omp simd
          for (int a = 0; a < 8; ++a) rows[r][a] += weight * column[a];
        }
      }
    }
    for (int a = 0; a < 8; ++a)
      for (int r = 0; r < 3; ++r) element.fe[r + 3 * a] = rows[r][a];
    for (int q = 0; q < 8; ++q) {
      double* vq = element.v_cache[q].data();
      for (int k = 0; k < 9; ++k) vq[k] = m.v[k][8 * j + q];
    }
  }
}

}  // namespace

bool PdHexEnergyAndForces(const PdHexElement* elements, int count) {
  DIFFPD_CHECK(count >= 1 && count <= kPdHexBatch, "PdHexEnergyAndForces: count = " << count);
  Svd3Lanes m;
  if (!PrepareLanes(elements, count, m)) return false;
  ComputeSvd3Lanes(m);
  LaneWeights w;
  bool any_volume = false;
  for (int j = 0; j < kPdHexBatch; ++j) {
    for (int q = 0; q < 8; ++q) {
      const int l = 8 * j + q;
      w.rotation[l] = j < count ? elements[j].weights.rotation : 0.0;
      w.volume[l] = j < count ? elements[j].weights.volume : 0.0;
      w.sample_volume[l] = j < count ? elements[j].sample_volume[q] : 0.0;
      any_volume = any_volume || w.volume[l] != 0.0;
    }
  }
  VolumeLanes b;
  if (any_volume) {
    for (int i = 0; i < 3; ++i)
      for (int l = 0; l < kLanes; ++l) b.s[i][l] = m.sigma[i][l];
    ProjectVolumeLanes(b);
    for (int l = 0; l < kLanes; ++l) {
      if (w.volume[l] == 0.0 || b.done[l] != 0.0) continue;
      const VolumeProjection single =
          ProjectSingularValuesToUnitDeterminant(Vec3(m.sigma[0][l], m.sigma[1][l], m.sigma[2][l]));
      for (int i = 0; i < 3; ++i) b.d[i][l] = single.d(i);
    }
  }
  LaneForces(m, any_volume ? b.d : m.sigma, w, elements, count);
  return true;
}

}  // namespace diffpd::internal
