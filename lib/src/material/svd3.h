// Signed singular value decomposition of 3x3 matrices (internal).
#pragma once

#include "diffpd/types.h"

namespace diffpd::internal {

// F = U diag(sigma) V^T with U, V proper rotations (det = +1),
// sigma(0) >= sigma(1) >= |sigma(2)|; sigma(2) < 0 exactly when det F < 0.
struct Svd3 {
  Mat3 U;
  Vec3 sigma;
  Mat3 V;
};

// Accurate to a few ulps in U, V orthogonality and in F reconstruction
// (relative to |F|), including repeated and zero singular values.
Svd3 ComputeSvd3(const Mat3& F);
// The same, with the Jacobi sweeps started from a rotation v_guess (det +1)
// instead of the identity: when v_guess is the V of a nearby F (the previous
// solver iteration at the same sample) one sweep plus the check usually
// suffices. The result does not depend on the guess beyond rounding.
Svd3 ComputeSvd3(const Mat3& F, const Mat3& v_guess);

// Up to kSvdBatch decompositions at once: out[i] = ComputeSvd3(F[i],
// v_guess[i]) for i < count, with the Jacobi sweeps of all matrices run
// together lane by lane (OpenMP SIMD; two hexahedra's 8 quadrature points
// fill a batch: with 8-wide vectors each step is two independent
// instructions, which hides the latency of the rotations' square roots and
// divisions). Each lane makes exactly its own scalar rotations, so the
// results match the scalar calls to rounding (bit for bit when the compiler
// contracts the same way); non-finite, zero or extreme-magnitude matrices
// take the scalar path. Pointers are not retained.
constexpr int kSvdBatch = 16;
void ComputeSvd3Batch(int count, const Mat3* F, const Mat3* v_guess, Svd3* out);

// The batch in structure-of-arrays form, for callers that already hold their
// matrices lane by lane (entry k = r + 3 c of lane l's matrix at [k][l]).
// In: b = F v_guess, v = v_guess, det_sign_reference = det(b), every lane
// finite with max |F(i, j)| in [1e-100, 1e100] (the unscaled path; idle lanes
// hold the identity). Out: b overwritten, v = V, u = U, sigma, each lane equal
// to ComputeSvd3(F, v_guess) up to rounding.
struct alignas(64) Svd3Lanes {
  double b[9][kSvdBatch];
  double v[9][kSvdBatch];
  double u[9][kSvdBatch];
  double sigma[3][kSvdBatch];
  double det_sign_reference[kSvdBatch];
};
void ComputeSvd3Lanes(Svd3Lanes& m);

}  // namespace diffpd::internal
