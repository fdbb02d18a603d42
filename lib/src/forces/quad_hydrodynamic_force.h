// Drag and thrust on one one-sided quad (internal); the model is documented
// in diffpd/quad_hydrodynamics.h. The force is the face's total: each corner
// receives a quarter.
#pragma once

#include <array>
#include <optional>
#include <vector>

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

// Which piece of the force a face is on: the one its state decides, or one
// held by StepInput::wetted_quads. A face held wet keeps the wet piece's
// formula past grazing incidence (phi < 0: the same polynomials continued);
// a face held dry feels nothing.
enum class FaceWater { kByState, kHeldWet, kHeldDry };
// Face f's: kByState where `wetted` is empty, else held as wetted[f] says.
inline FaceWater FaceWaterOf(const std::vector<char>& wetted, int f) {
  if (wetted.empty()) return FaceWater::kByState;
  return wetted[f] ? FaceWater::kHeldWet : FaceWater::kHeldDry;
}
// Throws InvalidInputError unless `wetted` is empty or has one entry, 0 or
// 1, per face of `water` (Scene::quad_hydrodynamics; none: no faces):
// "wetted_quads has 3 entries, expected 860 (one per quad_hydrodynamics face)",
// "wetted_quads[2] = 7 is invalid: must be 0 or 1".
void CheckWettedQuads(const std::vector<char>& wetted, const std::optional<QuadHydrodynamics>& water);

// F(p_0..p_3, u) for the relative velocity u = flow - mean corner velocity.
Vec3 QuadHydrodynamicForce(const QuadHydrodynamics& params, const std::array<Vec3, 4>& corners, const Vec3& u,
                           FaceWater water = FaceWater::kByState);

// Vector-Jacobian products with w (3-vector): (*g_corners)[i] = (dF/dp_i)^T w,
// *g_u = (dF/du)^T w, and dF/dtheta . w added to *grad for the fluid
// density and the curves' control values (the flow velocity's share is
// the caller's: u depends on it).
void QuadHydrodynamicForceVjp(const QuadHydrodynamics& params, const std::array<Vec3, 4>& corners, const Vec3& u,
                              const Vec3& w, std::array<Vec3, 4>* g_corners, Vec3* g_u, QuadHydrodynamicsGradient* grad,
                              FaceWater water = FaceWater::kByState);

}  // namespace diffpd::internal
