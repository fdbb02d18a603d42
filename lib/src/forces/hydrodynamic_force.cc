#include "forces/hydrodynamic_force.h"

#include <cmath>

#include <Eigen/Geometry>

namespace diffpd::internal {
namespace {

// Below these the force and its derivatives are zero to rounding (both terms
// are O(|u|^2) and O(|N|)).
constexpr double kTinySpeed = 1e-14;  // m/s
constexpr double kTinyArea = 1e-30;   // m^2

bool Degenerate(const Vec3& area_vector, const Vec3& u) {
  return u.norm() < kTinySpeed || area_vector.norm() < kTinyArea;
}

}  // namespace

HydrodynamicTerms EvaluateHydrodynamicTerms(const Vec3& area_vector, const Vec3& u) {
  HydrodynamicTerms t;
  if (Degenerate(area_vector, u)) return t;
  const double s = u.norm(), m = area_vector.norm(), p = area_vector.dot(u);
  t.t1 = m * s * u;
  t.t2 = (p * p / (m * s)) * u;
  t.t3 = (p * s / m) * area_vector;
  return t;
}

Vec3 HydrodynamicForce(const Hydrodynamics& params, const Vec3& area_vector, const Vec3& u) {
  const HydrodynamicTerms t = EvaluateHydrodynamicTerms(area_vector, u);
  return -0.5 * params.fluid_density *
         (params.drag_tangential * t.t1 + (params.drag_normal - params.drag_tangential) * t.t2 + params.thrust * t.t3);
}

void HydrodynamicForceVjp(const Hydrodynamics& params, const Vec3& area_vector, const Vec3& u, const Vec3& w,
                          Vec3* g_area, Vec3* g_velocity, StateForceGradient* grad) {
  g_area->setZero();
  g_velocity->setZero();
  if (Degenerate(area_vector, u)) return;
  const Vec3& N = area_vector;
  const double s = u.norm(), m = N.norm(), p = N.dot(u);
  const Vec3 uh = u / s, nh = N / m;
  const double uw = u.dot(w), nw = N.dot(w);
  // (dT/du)^T w and (dT/dN)^T w of the three terms.
  const Vec3 t1_u = m * (s * w + uw * uh);
  const Vec3 t1_n = (s * uw) * nh;
  const Vec3 t2_u = (p * p / (m * s)) * w + uw * ((2 * p / (m * s)) * N - (p * p / (m * s * s)) * uh);
  const Vec3 t2_n = uw * ((2 * p / (m * s)) * u - (p * p / (m * m * s)) * nh);
  const Vec3 t3_u = nw * ((s / m) * N + (p / m) * uh);
  const Vec3 t3_n = (p * s / m) * w + nw * ((s / m) * u - (p * s / (m * m)) * nh);
  const double ct = params.drag_tangential, cd = params.drag_normal - params.drag_tangential, cth = params.thrust;
  const double scale = -0.5 * params.fluid_density;
  *g_velocity = scale * (ct * t1_u + cd * t2_u + cth * t3_u);
  *g_area = scale * (ct * t1_n + cd * t2_n + cth * t3_n);
  if (grad) {
    const double w1 = w.dot(u) * m * s;      // w . T1
    const double w2 = uw * p * p / (m * s);  // w . T2
    const double w3 = nw * p * s / m;        // w . T3
    grad->fluid_density += -0.5 * (ct * w1 + cd * w2 + cth * w3);
    grad->drag_tangential += scale * (w1 - w2);
    grad->drag_normal += scale * w2;
    grad->thrust += scale * w3;
  }
}

}  // namespace diffpd::internal
