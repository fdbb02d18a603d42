#include "forces/quad_hydrodynamic_force.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>

#include "diffpd/error.h"
#include "diffpd/wetted_quads.h"

namespace diffpd::internal {
namespace {

// Below these the force is zero to rounding (it is O(|u|^2) and O(area)).
constexpr double kTinySpeed = 1e-14;  // m/s
constexpr double kTinyArea = 1e-30;   // m^2
// Floor of sqrt(1 - c^2) in d phi / dc (a face moving exactly along its normal).
constexpr double kMinSine = 1e-8;

// The corner triangles (a, b, c): c_t = (p_b - p_a) x (p_c - p_b).
constexpr int kTriangles[4][3] = {{0, 1, 2}, {0, 2, 3}, {0, 1, 3}, {3, 1, 2}};

struct Geometry {
  std::array<Vec3, 4> cross;
  Vec3 sum = Vec3::Zero();
  double sum_norm = 0;
  Vec3 normal = Vec3::Zero();
  double area = 0;
};

Geometry FaceGeometry(const std::array<Vec3, 4>& p) {
  Geometry g;
  for (int t = 0; t < 4; ++t) {
    const int a = kTriangles[t][0], b = kTriangles[t][1], c = kTriangles[t][2];
    g.cross[t] = (p[b] - p[a]).cross(p[c] - p[b]);
    g.sum += g.cross[t];
    g.area += 0.25 * g.cross[t].norm();
  }
  g.sum_norm = g.sum.norm();
  if (g.sum_norm >= kTinyArea) g.normal = g.sum / g.sum_norm;
  return g;
}

// The face's geometry where it feels the water: the relative velocity u
// (|u| = speed) is not negligible, the face not degenerate, and, unless it is
// held wet, u points against the face's outward normal (cos = n . u / |u| <
// 0); none otherwise (no force), and none for a face held dry.
std::optional<Geometry> WetGeometry(const std::array<Vec3, 4>& corners, const Vec3& u, double speed, FaceWater water) {
  if (water == FaceWater::kHeldDry || speed < kTinySpeed) return std::nullopt;
  const Geometry g = FaceGeometry(corners);
  if (g.sum_norm < kTinyArea) return std::nullopt;
  if (water == FaceWater::kByState && !(g.normal.dot(u) / speed < 0)) return std::nullopt;
  return g;
}

// The angle phi and both coefficients at cos = n . d: phi > 0 where the
// water meets the face (cos < 0), so t_drag = 2 |phi| / pi = 2 phi / pi;
// a face held wet past grazing incidence (cos >= 0) continues the same
// polynomials to phi <= 0.
struct Coefficients {
  double phi, drag, thrust, t_drag, t_thrust;
};

Coefficients Evaluate(const QuadHydrodynamics& params, double cosine) {
  Coefficients k;
  k.phi = std::acos(std::clamp(cosine, -1.0, 1.0)) - M_PI / 2;
  k.t_drag = k.phi / (M_PI / 2);
  k.t_thrust = k.phi / M_PI + 0.5;
  k.drag = params.drag_curve.dot(BezierBasis(k.t_drag));
  k.thrust = params.thrust_curve.dot(BezierBasis(k.t_thrust));
  return k;
}

}  // namespace

Eigen::Vector4d BezierBasis(double t) {
  const double s = 1 - t;
  return Eigen::Vector4d(s * s * s, 3 * t * s * s, 3 * t * t * s, t * t * t);
}

double BezierDerivative(const Eigen::Vector4d& b, double t) {
  const double s = 1 - t;
  return 3 * ((b(1) - b(0)) * s * s + 2 * (b(2) - b(1)) * t * s + (b(3) - b(2)) * t * t);
}

std::array<Vec3, 4> QuadCorners(const VectorXd& x, const Eigen::Matrix4Xi& quads, int f) {
  return {x.segment<3>(3 * quads(0, f)), x.segment<3>(3 * quads(1, f)), x.segment<3>(3 * quads(2, f)),
          x.segment<3>(3 * quads(3, f))};
}

Vec3 QuadRelativeVelocity(const VectorXd& v, const QuadHydrodynamics& q, int f) {
  Vec3 mean = Vec3::Zero();
  for (int c = 0; c < 4; ++c) mean += v.segment<3>(3 * q.quads(c, f));
  return q.flow_velocity - mean / 4.0;
}

bool FaceMeetsWater(const std::array<Vec3, 4>& corners, const Vec3& u) {
  const double speed = u.norm();
  return WetGeometry(corners, u, speed, FaceWater::kByState).has_value();
}

void CheckWettedQuads(const std::vector<char>& wetted, const std::optional<QuadHydrodynamics>& water) {
  if (wetted.empty()) return;
  const long num_faces = water ? water->quads.cols() : 0;
  std::ostringstream msg;
  if (static_cast<long>(wetted.size()) != num_faces) {
    msg << "wetted_quads has " << wetted.size() << " entries, expected " << num_faces
        << " (one per quad_hydrodynamics face)";
    throw InvalidInputError(msg.str());
  }
  for (size_t f = 0; f < wetted.size(); ++f)
    if (wetted[f] != 0 && wetted[f] != 1) {
      msg << "wetted_quads[" << f << "] = " << static_cast<int>(wetted[f]) << " is invalid: must be 0 or 1";
      throw InvalidInputError(msg.str());
    }
}

Vec3 QuadHydrodynamicForce(const QuadHydrodynamics& params, const std::array<Vec3, 4>& corners, const Vec3& u,
                           FaceWater water) {
  const double speed = u.norm();
  const std::optional<Geometry> g = WetGeometry(corners, u, speed, water);
  if (!g) return Vec3::Zero();
  const double cosine = g->normal.dot(u) / speed;
  const Coefficients k = Evaluate(params, cosine);
  return 0.5 * params.fluid_density * g->area * speed * (k.drag * u - k.thrust * speed * g->normal);
}

void QuadHydrodynamicForceVjp(const QuadHydrodynamics& params, const std::array<Vec3, 4>& corners, const Vec3& u,
                              const Vec3& w, std::array<Vec3, 4>* g_corners, Vec3* g_u, QuadHydrodynamicsGradient* grad,
                              FaceWater water) {
  for (Vec3& g : *g_corners) g.setZero();
  g_u->setZero();
  const double s = u.norm();
  const std::optional<Geometry> wet = WetGeometry(corners, u, s, water);
  if (!wet) return;
  const Geometry& g = *wet;
  const Vec3& n = g.normal;
  const double c = n.dot(u) / s;
  const Coefficients k = Evaluate(params, c);
  const double half_rho = 0.5 * params.fluid_density, a = g.area;
  const double wu = w.dot(u), wn = w.dot(n);
  // w . dF/dCd and w . dF/dCt.
  const double w_drag = half_rho * a * s * wu, w_thrust = -half_rho * a * s * s * wn;
  // phi = arccos(c) - pi/2: dphi/dc = -1 / sqrt(1 - c^2).
  const double dphi_dc = -1.0 / std::max(std::sqrt(std::max(1 - c * c, 0.0)), kMinSine);
  const double g_c = w_drag * BezierDerivative(params.drag_curve, k.t_drag) * (2 / M_PI) * dphi_dc +
                     w_thrust * BezierDerivative(params.thrust_curve, k.t_thrust) * (1 / M_PI) * dphi_dc;
  // c = n . u / |u|: dc/du = (n - c u / s) / s, dc/dn = u / s.
  *g_u = half_rho * a * (k.drag * (s * w + (wu / s) * u) - 2 * k.thrust * wn * u) + (g_c / s) * (n - (c / s) * u);
  const Vec3 g_n = -half_rho * a * s * s * k.thrust * w + (g_c / s) * u;
  const double g_area = half_rho * s * (k.drag * wu - k.thrust * s * wn);
  // n = sum / |sum|, A = (1/4) sum_t |c_t|.
  const Vec3 g_sum = (g_n - n * n.dot(g_n)) / g.sum_norm;
  for (int t = 0; t < 4; ++t) {
    Vec3 gc = g_sum;
    const double norm = g.cross[t].norm();
    if (norm > 0) gc += (0.25 * g_area / norm) * g.cross[t];
    const int ia = kTriangles[t][0], ib = kTriangles[t][1], ic = kTriangles[t][2];
    const Vec3 e1 = corners[ib] - corners[ia], e2 = corners[ic] - corners[ib];
    // g . d(e1 x e2) = de1 . (e2 x g) + de2 . (g x e1).
    const Vec3 t1 = e2.cross(gc), t2 = gc.cross(e1);
    (*g_corners)[ia] -= t1;
    (*g_corners)[ib] += t1 - t2;
    (*g_corners)[ic] += t2;
  }
  if (grad) {
    grad->fluid_density += 0.5 * a * s * (k.drag * wu - k.thrust * s * wn);
    grad->drag_curve += w_drag * BezierBasis(k.t_drag);
    grad->thrust_curve += w_thrust * BezierBasis(k.t_thrust);
  }
}

}  // namespace diffpd::internal

namespace diffpd {

std::vector<char> WettedQuads(const QuadHydrodynamics& water, const VectorXd& x, const VectorXd& v) {
  std::vector<char> wetted(water.quads.cols(), 0);
  for (int f = 0; f < static_cast<int>(water.quads.cols()); ++f)
    wetted[f] =
        internal::FaceMeetsWater(internal::QuadCorners(x, water.quads, f), internal::QuadRelativeVelocity(v, water, f));
  return wetted;
}

Eigen::Matrix3Xd QuadRelativeVelocities(const QuadHydrodynamics& water, const VectorXd& v) {
  Eigen::Matrix3Xd u(3, water.quads.cols());
  for (int f = 0; f < static_cast<int>(water.quads.cols()); ++f) u.col(f) = internal::QuadRelativeVelocity(v, water, f);
  return u;
}

}  // namespace diffpd
