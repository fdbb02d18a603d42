// Contact with fixed collision surfaces: frictional (active set, DiffPD Sec.
// 5.2) and penalty (a smooth PD vertex energy).
//
// Frictional contact. At every implicit step an active-set loop decides which
// candidate nodes touch the surface; those become Dirichlet nodes for that
// step only (all three axes: static friction, the node sticks where it
// touches), pinned at the projection of their previous position onto the
// surface,
//
//   p(x_i) = Project(x_i)
//
// (a node resting on the surface stays where it is; an arriving node lands
// at the surface point below where it was, so its tangential motion stops in
// the step it lands, an O(h |v_t|) difference from the exact entry point
// that keeps p smooth: the entry point of a grazing segment jumps with the
// node's height, which would make gradients meaningless). The loop starts
// from the candidates whose predicted position x_i + h v_i has gap <= 1e-9 m, solves the
// step with them pinned, then releases every pinned node whose contact force
// pulls it into the surface (n . f_c < 0, f_c = grad g at the node) and adds
// every free candidate deeper than `penetration_tolerance`; it repeats until
// the set no longer changes, at most `max_passes` solves per step, else
// SolverError(kActiveSetNotConverged). A node released and re-added within one
// step is not released again in that step (no cycling). Only passes solved to
// the step's tolerance lock a node, so that the loose solves of screening
// (below) cannot choose the final set. Each step's active
// set and contact forces are recorded in its StepReport.
//
// Energy. Sticking friction and inelastic landing only take energy out, but
// the pins are not where the unconstrained step would put the nodes: a
// landing node is pinned where its previous position projects, up to
// h |v| from where it would touch, and the pinned positions hold whatever the
// elements between them store. Where a node moves far in one step compared
// with the cells (large h, a coarse or very stiff body), that stored energy
// can exceed what the step took out (a one-cell ball dropped at h = 0.1 s
// was pinned squashed flat, 1.5e6 J from 0.6 J). After the set settles,
// a step with pinned nodes is therefore checked: its total energy
//   T = 1/2 v^T M v + E(x) - f . x        (f: the step's explicit force)
// may rise over the previous state's by at most max_energy_gain times the
// energies involved (1/2 v^T M v and E of both states and |f . (x_i+1 - x_i)|)
// plus the solve's own slack (|grad g| |x_i+1 - x_i|); more throws
// SolverError(kContactEnergyGain) naming both energies. Steps at ordinary
// time steps lose energy (measured in docs/benchmarks.md, "Stability at the
// extremes"). With
// screening_rel_tolerance = r > rel_tolerance, each pass's solve pauses at a
// checkpoint, the first iterate with |grad g| <= abs_tolerance + r |grad g(x0)|,
// and applies the test there (screening): if the set changes, the pass ends
// and the next one starts from that iterate; if not, the same solve goes on
// to the step's tolerance, its state (PD-LBFGS's curvature pairs) intact, and
// screening ends for the step (it also ends when a node released on a loose
// solve comes back). The final set is checked once more at the step's
// tolerance; the returned step meets the same tolerance and the same
// complementarity test as without screening, at fewer iterations when the
// set changes often.
//
// The PD matrix A is never refactorised when the active set changes: the
// erased rows and columns are a low-rank change handled by the
// Sherman-Morrison-Woodbury identity on the existing factor, in the forward
// and the backward pass (kRefactorize instead factorises the erased matrix;
// same solution, for comparison and benchmarks). Newton methods pin the same
// nodes as extra fixed DoFs. Semi-implicit Euler does not support frictional
// contact (Step throws InvalidInputError); SolveQuasiStatic ignores it (there
// is no previous state to pin from).
//
// Gradients: the backward pass holds each step's recorded active set fixed, so
// the gradient is that of the smooth piece of the trajectory on which the
// rollout lies (the active set is piecewise constant in the inputs; a
// perturbation that changes it leaves that piece). Pins are differentiated
// through p(x_i).
//
// Penalty contact. The half-space H = {x : n . x >= offset} repels candidate
// nodes with the PD vertex energy
//
//   E(x) = (w/2) |x - Proj_H(x)|^2 = (w/2) min(0, n . x - offset)^2,
//
// w = stiffness (N/m); PD adds w to A's diagonal at every candidate node.
// Optional Coulomb-like friction is an explicit state force evaluated at
// (x_i, v_i) on every penetrating candidate:
//
//   f = -mu f_n v_t / sqrt(|v_t|^2 + eps^2),   f_n = w (offset - n . x_i),
//   v_t = v_i - (n . v_i) n,  eps = friction_velocity,
//
// smooth in the state (explicit: keep mu f_n h / (eps m) < 2 for stability).
//
// Scene::Validate rejects, with InvalidInputError, e.g.:
//   "scene: frictional_contacts[0].surface.normal = (0, 0, 0) is invalid: must be finite with non-zero length",
//   "scene: frictional_contacts[0].surface.radius = 0 is invalid: must be finite and > 0 (m)",
//   "scene: frictional_contacts[0].surface: a height field needs both height and height_gradient",
//   "scene: frictional_contacts[0].surface.kind = 7 is invalid: must be kPlane (0), kSphere (1) or kHeightField (2)",
//   "scene: frictional_contacts[0].nodes[2] = 45 is out of range [0, 45) (no such node)",
//   "scene: node 40 is a candidate of frictional_contacts[0] and frictional_contacts[1] (a node may be a
//    frictional contact candidate once)",
//   "scene: frictional_contacts[0].nodes[2] = 0 has a Dirichlet DoF; frictional contact candidates must be free",
//   "scene: frictional_contact_options.pd_linear_solve = 5 is invalid: must be kWoodbury (0) or kRefactorize (1)",
//   "scene: frictional_contact_options.max_passes = 0 is invalid: must be >= 1",
//   "scene: frictional_contact_options.penetration_tolerance = -1 is invalid: must be finite and >= 0 (m)",
//   "scene: frictional_contact_options.screening_rel_tolerance = 1 is invalid: must be finite and in [0, 1)",
//   "scene: frictional_contact_options.max_energy_gain = -1 is invalid: must be >= 0 (infinity: no check)",
//   "scene: penalty_contacts[0].stiffness = 0 is invalid: must be finite and > 0 (N/m)",
//   "scene: penalty_contacts[0].friction = nan is invalid: must be finite and >= 0"
// (likewise normal, offset, friction_velocity of penalty contacts).
#pragma once

#include <functional>
#include <vector>

#include "diffpd/types.h"

namespace diffpd {

// A fixed collision surface. The body stays on the side where gap(x) >= 0.
struct ContactSurface {
  enum class Kind {
    kPlane,        // n . x = offset; outside n . x > offset (n normalised)
    kSphere,       // |x - center| = radius; the body stays outside the ball
    kHeightField,  // z = height(x, y); the body stays above (z > height)
  };
  Kind kind = Kind::kPlane;
  Vec3 normal = Vec3(0, 0, 1);  // plane: outward normal, finite, non-zero
  double offset = 0;            // plane: m
  Vec3 center = Vec3::Zero();   // sphere: m
  double radius = 1;            // sphere: m, finite and > 0
  // Height field: height(x, y) in m and its gradient (dh/dx, dh/dy); both
  // required, smooth where contact happens.
  std::function<double(double, double)> height;
  std::function<Eigen::Vector2d(double, double)> height_gradient;

  static ContactSurface Plane(const Vec3& normal, double offset);
  static ContactSurface Sphere(const Vec3& center, double radius);
  static ContactSurface HeightField(std::function<double(double, double)> height,
                                    std::function<Eigen::Vector2d(double, double)> height_gradient);

  // Signed gap (m for plane and sphere; vertical distance for a height field):
  // > 0 outside, < 0 penetrating.
  double Gap(const Vec3& x) const;
  // Gradient of Gap (unit outward normal for plane and sphere;
  // (-dh/dx, -dh/dy, 1) for a height field).
  Vec3 GapGradient(const Vec3& x) const;
  // The point of the surface a node is pinned to from x: orthogonal projection
  // for plane and sphere (x = center maps to the top of the sphere), vertical
  // projection (x, y, height(x, y)) for a height field.
  Vec3 Project(const Vec3& x) const;
  // d Project / dx (3x3).
  Mat3 ProjectJacobian(const Vec3& x) const;
};

// How PD solves with the active set erased from the prefactorised A.
enum class ContactLinearSolve {
  kWoodbury,     // low-rank (Sherman-Morrison-Woodbury) update of A's factor
  kRefactorize,  // factorise A with the active rows and columns erased
};

struct FrictionalContact {
  ContactSurface surface;
  // Candidate nodes (each at most once across all frictional contacts, none
  // with a Dirichlet DoF).
  std::vector<int> nodes;
};

// Settings of the active-set loop shared by all frictional contacts.
struct FrictionalContactOptions {
  int max_passes = 20;                  // solves per step, >= 1
  double penetration_tolerance = 1e-6;  // m, >= 0: a free candidate deeper than this joins the set
  // Relative tolerance of the screening solves (see above), finite and in
  // [0, 1); 0 or <= the step's rel_tolerance: no screening.
  double screening_rel_tolerance = 0;
  ContactLinearSolve pd_linear_solve = ContactLinearSolve::kWoodbury;
  // Largest rise of the total energy in a step with pinned nodes, relative
  // to the energies involved (see "Energy" above); >= 0, infinity: no check.
  // The default lies between the largest gain measured on a converged step
  // of a scene that rolls on its contact (4.8e-4, the paper's rolling
  // sphere at h = 5 ms) and the smallest of a refused blow-up (1.1e-2, the
  // stress grids at h = 0.1 s).
  double max_energy_gain = 1e-3;
};

struct PenaltyContact {
  Vec3 normal = Vec3(0, 0, 1);      // outward normal of the allowed half-space, non-zero
  double offset = 0;                // m: the half-space is n . x >= offset (n normalised)
  std::vector<int> nodes;           // candidate nodes
  double stiffness = 1e4;           // w, N/m, finite and > 0
  double friction = 0;              // mu, finite and >= 0 (0: frictionless, no state force)
  double friction_velocity = 1e-2;  // eps, m/s, finite and > 0
};

}  // namespace diffpd
