// Drag and thrust on one triangle (internal); the model is documented in
// diffpd/state_forces.h. In terms of the area vector N = (x_b - x_a) x
// (x_c - x_a) / 2 (|N| = A, N / |N| = n) and the relative velocity u:
//
//   F(N, u) = -(rho_f / 2) [ ct T1 + (cn - ct) T2 + cth T3 ],
//   T1 = |N| |u| u,   T2 = (N . u)^2 / (|N| |u|) u,   T3 = (N . u) |u| N / |N|,
//
// ct = drag_tangential, cn = drag_normal, cth = thrust. F and its first
// derivatives vanish at u = 0 (and for a degenerate triangle, |N| = 0).
#pragma once

#include "diffpd/state_forces.h"
#include "diffpd/types.h"

namespace diffpd::internal {

// The three terms T1, T2, T3 (each a 3-vector) at (N, u).
struct HydrodynamicTerms {
  Vec3 t1 = Vec3::Zero(), t2 = Vec3::Zero(), t3 = Vec3::Zero();
};
HydrodynamicTerms EvaluateHydrodynamicTerms(const Vec3& area_vector, const Vec3& u);

// F(N, u) for the given parameters.
Vec3 HydrodynamicForce(const Hydrodynamics& params, const Vec3& area_vector, const Vec3& u);

// Vector-Jacobian products with w (3-vector): *g_area = (dF/dN)^T w,
// *g_velocity = (dF/du)^T w; and dF/dtheta . w for the parameters into *grad
// (fluid_density, drag_tangential, drag_normal, thrust are incremented).
void HydrodynamicForceVjp(const Hydrodynamics& params, const Vec3& area_vector, const Vec3& u, const Vec3& w,
                          Vec3* g_area, Vec3* g_velocity, StateForceGradient* grad);

}  // namespace diffpd::internal
