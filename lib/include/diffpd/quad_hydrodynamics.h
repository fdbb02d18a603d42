// Hydrodynamics of the original DiffPD swimmers (starfish, water snake):
// drag and thrust on one-sided quadrilateral faces with Bezier coefficient
// curves. A variant of Hydrodynamics (state_forces.h), declared as
// Scene::quad_hydrodynamics; both may be declared and their forces add up.
//
// Per quad (p_0, p_1, p_2, p_3) at positions x_i, velocities v_i:
//   u = flow_velocity - (v_0 + v_1 + v_2 + v_3) / 4   (the water's velocity
//       relative to the face), d = u / |u|;
//   c_t = (p_b - p_a) x (p_c - p_b) over the corner triangles (a, b, c) =
//       (0,1,2), (0,2,3), (0,1,3), (3,1,2); n = sum_t c_t / |sum_t c_t|,
//       A = (1/4) sum_t |c_t| (the quad's area when planar);
//   only a face moving into the water counts: n . d < 0, and then
//       phi = arccos(n . d) - pi/2 in (0, pi/2];
//   drag    f_d =  (rho_f / 2) A Cd(phi) |u| u,
//   thrust  f_t = -(rho_f / 2) A Ct(phi) |u|^2 n,
//   Cd(phi) = B(drag_curve; 2 phi / pi),  Ct(phi) = B(thrust_curve; phi / pi + 1/2),
//   B(b; t) = b_0 (1-t)^3 + 3 b_1 t (1-t)^2 + 3 b_2 t^2 (1-t) + b_3 t^3,
// and each corner receives (f_d + f_t) / 4. Forces are explicit (evaluated
// at the start of the step) and differentiated w.r.t. x, v and the
// parameters (StateForceGradient::quad_hydrodynamics). The force jumps
// where a face turns (n . d = 0); d phi / d(n . d) = -1 / sqrt(1 - (n . d)^2)
// is capped at 1e8 where a face moves exactly along its normal.
// StepInput::wetted_quads (rollout.h) can hold a step's faces wet or dry
// instead: a face held wet where n . d >= 0 keeps the formulas above with
// phi <= 0 (Cd(phi) = B(drag_curve; 2 phi / pi), the same polynomial).
//
// Scene::Validate rejects, with InvalidInputError, e.g.:
//   "scene: quad_hydrodynamics.quads(3, 5) = 99 is out of range [0, 45) (no such node)",
//   "scene: quad_hydrodynamics.fluid_density = -1 is invalid: must be finite and >= 0 (kg/m^3)",
//   "scene: quad_hydrodynamics.drag_curve = (0.05, nan, 1.85, 2.05) is invalid: must be finite",
//   "scene: quad_hydrodynamics.flow_velocity = (0, inf, 0) is invalid: must be finite (m/s)".
#pragma once

#include <Eigen/Core>

#include "diffpd/mesh.h"
#include "diffpd/types.h"

namespace diffpd {

struct QuadHydrodynamics {
  // 4 x F node indices of the wetted faces, each a cycle whose
  // (p_1 - p_0) x (p_2 - p_1) points into the water (see BoundaryQuads).
  Eigen::Matrix4Xi quads;
  double fluid_density = 1e3;         // rho_f, kg/m^3, finite and >= 0
  Vec3 flow_velocity = Vec3::Zero();  // m/s, finite
  // Bezier control values of Cd and Ct (finite); defaults: the original's.
  Eigen::Vector4d drag_curve = Eigen::Vector4d(0.05, 0.05, 1.85, 2.05);
  Eigen::Vector4d thrust_curve = Eigen::Vector4d(-0.8, -0.5, 0.1, 2.5);
};

// dL/d(parameter) of QuadHydrodynamics.
struct QuadHydrodynamicsGradient {
  double fluid_density = 0;           // per kg/m^3
  Vec3 flow_velocity = Vec3::Zero();  // per m/s
  Eigen::Vector4d drag_curve = Eigen::Vector4d::Zero();
  Eigen::Vector4d thrust_curve = Eigen::Vector4d::Zero();
};

// The quadrilateral faces used by exactly one hexahedron of a hex mesh, as
// outward cycles (4 x F node indices; (p_1 - p_0) x (p_2 - p_1) points away
// from the element at rest). Throws InvalidInputError for a mesh that is
// not hexahedral ("BoundaryQuads: the mesh has tet4 elements; quads need hex8").
Eigen::Matrix4Xi BoundaryQuads(const Mesh& mesh);

}  // namespace diffpd
