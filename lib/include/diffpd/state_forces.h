// Forces that depend on the state (x_i, v_i) at the start of a step. They are
// explicit: evaluated once per step at (x_i, v_i) and added to the step's
// force f (like gravity), and the backward pass differentiates them w.r.t. the
// state and their parameters (RolloutGradient::state_forces).
//
// Linear damping (Scene::linear_damping = c, 1/s, finite and >= 0):
//   f = -c M v_i   (mass-proportional; M the lumped mass).
//
// Hydrodynamics (Scene::hydrodynamics), drag and thrust on surface triangles
// for swimmers, after the starfish model of Du et al. (RA-L 2021). For each
// triangle (a, b, c) at positions x_i: area A, unit normal n (right-handed
// (x_b - x_a) x (x_c - x_a), outward for BoundaryTriangles), the relative
// velocity u = (v_a + v_b + v_c) / 3 - flow_velocity and the angle of attack
// phi between u and the triangle's plane, sin(phi) = |n . u| / |u|:
//
//   drag    f_d = -(rho_f / 2) A Cd(phi) |u| u,
//           Cd(phi) = drag_tangential + (drag_normal - drag_tangential) sin(phi)^2,
//   thrust  f_t = -(rho_f / 2) A Ct(phi) |u|^2 sign(n . u) n,
//           Ct(phi) = thrust sin(phi),
//
// i.e. f_t = -(rho_f / 2) A thrust (n . u) |u| n: a pressure force normal to
// the triangle that opposes its normal motion (a paddle stroke pushes the
// body the other way). Cd rises smoothly from drag_tangential (flow along the
// face) to drag_normal (flow normal to it); defaults 0.05 and 2.05 follow the
// starfish fact sheet. Each triangle's force is shared equally by its three
// nodes. Both terms are O(|u|^2): zero with zero derivative at u = 0.
//
// Scene::Validate rejects, with InvalidInputError, e.g.:
//   "scene: hydrodynamics.triangles(2, 5) = 99 is out of range [0, 45) (no such node)",
//   "scene: hydrodynamics.fluid_density = nan is invalid: must be finite and >= 0 (kg/m^3)",
//   "scene: hydrodynamics.drag_normal = inf is invalid: must be finite and >= 0" (also drag_tangential),
//   "scene: hydrodynamics.thrust = nan is invalid: must be finite",
//   "scene: hydrodynamics.flow_velocity = (0, inf, 0) is invalid: must be finite (m/s)",
//   "scene: linear_damping = -2 is invalid: must be finite and >= 0 (1/s)".
#pragma once

#include <vector>

#include <Eigen/Core>

#include "diffpd/mesh.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/types.h"

namespace diffpd {

struct Hydrodynamics {
  // 3 x t node indices of the wetted triangles (see BoundaryTriangles).
  Eigen::Matrix3Xi triangles;
  double fluid_density = 1e3;         // rho_f, kg/m^3, finite and >= 0
  double drag_tangential = 0.05;      // Cd at phi = 0, finite and >= 0
  double drag_normal = 2.05;          // Cd at phi = 90 degrees, finite and >= 0
  double thrust = 0.0;                // Ct at phi = 90 degrees, finite (any sign)
  Vec3 flow_velocity = Vec3::Zero();  // m/s, finite
};

// dL/d(parameter) of the declared state forces (zero where not declared).
struct StateForceGradient {
  double linear_damping = 0;  // per (1/s)
  double fluid_density = 0;   // per kg/m^3
  double drag_tangential = 0;
  double drag_normal = 0;
  double thrust = 0;
  Vec3 flow_velocity = Vec3::Zero();             // per m/s
  std::vector<double> penalty_friction;          // per Scene::penalty_contacts entry, dL/dmu
  QuadHydrodynamicsGradient quad_hydrodynamics;  // Scene::quad_hydrodynamics (quad_hydrodynamics.h)
};

// Boundary faces of a mesh as outward triangles (3 x t node indices): faces
// used by exactly one element; a hexahedron's quadrilateral face is split
// into two triangles along one diagonal. Outward means (x_b - x_a) x (x_c - x_a)
// points away from the element at rest. Does not validate the mesh.
Eigen::Matrix3Xi BoundaryTriangles(const Mesh& mesh);
// Sorted indices of the nodes on the boundary faces.
std::vector<int> BoundaryNodes(const Mesh& mesh);

}  // namespace diffpd
