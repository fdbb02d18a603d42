// Drag and thrust on one one-sided quad (internal); the model is documented
// in diffpd/quad_hydrodynamics.h. The force is the face's total: each corner
// receives a quarter.
#pragma once

#include <array>

#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/types.h"

namespace diffpd::internal {

// The Bezier curve B(b; t) and its basis (1-t)^3, 3t(1-t)^2, 3t^2(1-t), t^3.
Eigen::Vector4d BezierBasis(double t);
double BezierDerivative(const Eigen::Vector4d& b, double t);  // dB/dt

// Corner positions of quad f of `quads` (4 x F node indices) at x (3n), and
// the water's velocity relative to quad f at velocities v (3n).
std::array<Vec3, 4> QuadCorners(const VectorXd& x, const Eigen::Matrix4Xi& quads, int f);
Vec3 QuadRelativeVelocity(const VectorXd& v, const QuadHydrodynamics& q, int f);

// Whether the water meets the face (its force is not zero): u is not
// negligible and points against the face's outward normal.
bool FaceMeetsWater(const std::array<Vec3, 4>& corners, const Vec3& u);

// F(p_0..p_3, u) for the relative velocity u = flow - mean corner velocity.
Vec3 QuadHydrodynamicForce(const QuadHydrodynamics& params, const std::array<Vec3, 4>& corners, const Vec3& u);

// Vector-Jacobian products with w (3-vector): (*g_corners)[i] = (dF/dp_i)^T w,
// *g_u = (dF/du)^T w, and dF/dtheta . w added to *grad for the fluid
// density and the curves' control values (the flow velocity's share is
// the caller's: u depends on it).
void QuadHydrodynamicForceVjp(const QuadHydrodynamics& params, const std::array<Vec3, 4>& corners, const Vec3& u,
                              const Vec3& w, std::array<Vec3, 4>* g_corners, Vec3* g_u,
                              QuadHydrodynamicsGradient* grad);

}  // namespace diffpd::internal
