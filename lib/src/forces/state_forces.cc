#include "forces/state_forces.h"

#include <array>
#include <cmath>

#include <Eigen/Geometry>

#include "forces/hydrodynamic_force.h"
#include "forces/quad_hydrodynamic_force.h"

namespace diffpd::internal {
namespace {

Vec3 AreaVector(const VectorXd& x, int a, int b, int c) {
  const Vec3 xa = x.segment<3>(3 * a);
  return 0.5 * (x.segment<3>(3 * b) - xa).cross(x.segment<3>(3 * c) - xa);
}

Vec3 MeanVelocity(const VectorXd& v, int a, int b, int c) {
  return (v.segment<3>(3 * a) + v.segment<3>(3 * b) + v.segment<3>(3 * c)) / 3.0;
}

}  // namespace

StateForces::StateForces(const Scene& scene)
    : damping_(scene.linear_damping),
      hydro_(scene.hydrodynamics),
      quad_hydro_(scene.quad_hydrodynamics),
      num_penalty_contacts_(static_cast<int>(scene.penalty_contacts.size())) {
  for (size_t c = 0; c < scene.penalty_contacts.size(); ++c) {
    const PenaltyContact& pc = scene.penalty_contacts[c];
    if (pc.friction == 0) continue;
    for (const int i : pc.nodes)
      friction_.push_back(FrictionNode{static_cast<int>(c), i, pc.normal.normalized(), pc.offset, pc.stiffness,
                                       pc.friction, pc.friction_velocity});
  }
}

void StateForces::Add(const VectorXd& x, const VectorXd& v, const VectorXd& mass, const std::vector<char>& wetted_quads,
                      VectorXd* f) const {
  if (empty()) return;
  if (damping_) f->array() -= *damping_ * mass.array() * v.array();
  if (hydro_) {
    const Eigen::Matrix3Xi& tri = hydro_->triangles;
    for (int t = 0; t < tri.cols(); ++t) {
      const int a = tri(0, t), b = tri(1, t), c = tri(2, t);
      const Vec3 u = MeanVelocity(v, a, b, c) - hydro_->flow_velocity;
      const Vec3 share = HydrodynamicForce(*hydro_, AreaVector(x, a, b, c), u) / 3.0;
      f->segment<3>(3 * a) += share;
      f->segment<3>(3 * b) += share;
      f->segment<3>(3 * c) += share;
    }
  }
  if (quad_hydro_) {
    for (int q = 0; q < quad_hydro_->quads.cols(); ++q) {
      const Vec3 share =
          internal::QuadHydrodynamicForce(*quad_hydro_, QuadCorners(x, quad_hydro_->quads, q),
                                          QuadRelativeVelocity(v, *quad_hydro_, q), FaceWaterOf(wetted_quads, q)) /
          4.0;
      for (int c = 0; c < 4; ++c) f->segment<3>(3 * quad_hydro_->quads(c, q)) += share;
    }
  }
  for (const FrictionNode& fn : friction_) {
    const double gap = fn.normal.dot(x.segment<3>(3 * fn.node)) - fn.offset;
    if (gap >= 0) continue;
    const Vec3 vi = v.segment<3>(3 * fn.node);
    const Vec3 vt = vi - fn.normal.dot(vi) * fn.normal;
    const double s = std::sqrt(vt.squaredNorm() + fn.eps * fn.eps);
    f->segment<3>(3 * fn.node) += (fn.mu * fn.stiffness * gap / s) * vt;  // -mu f_n vt / s, f_n = -w gap
  }
}

void StateForces::AddVjp(const VectorXd& x, const VectorXd& v, const VectorXd& mass,
                         const std::vector<char>& wetted_quads, const VectorXd& w, VectorXd* gx, VectorXd* gv,
                         StateForceGradient* grad, VectorXd* dmass) const {
  if (empty()) return;
  if (damping_) {
    const VectorXd mw = mass.cwiseProduct(w);
    gv->noalias() -= *damping_ * mw;
    grad->linear_damping -= mw.dot(v);
    if (dmass) dmass->noalias() -= *damping_ * w.cwiseProduct(v);
  }
  if (hydro_) {
    const Eigen::Matrix3Xi& tri = hydro_->triangles;
    for (int t = 0; t < tri.cols(); ++t) {
      const int a = tri(0, t), b = tri(1, t), c = tri(2, t);
      const Vec3 wt = (w.segment<3>(3 * a) + w.segment<3>(3 * b) + w.segment<3>(3 * c)) / 3.0;
      const Vec3 u = MeanVelocity(v, a, b, c) - hydro_->flow_velocity;
      const Vec3 xa = x.segment<3>(3 * a);
      const Vec3 e1 = x.segment<3>(3 * b) - xa, e2 = x.segment<3>(3 * c) - xa;
      Vec3 g_area, g_u;
      HydrodynamicForceVjp(*hydro_, 0.5 * e1.cross(e2), u, wt, &g_area, &g_u, grad);
      // N = e1 x e2 / 2: g . dN = de1 . (e2 x g) / 2 + de2 . (g x e1) / 2.
      const Vec3 gb = 0.5 * e2.cross(g_area), gc = 0.5 * g_area.cross(e1);
      gx->segment<3>(3 * a) -= gb + gc;
      gx->segment<3>(3 * b) += gb;
      gx->segment<3>(3 * c) += gc;
      for (const int i : {a, b, c}) gv->segment<3>(3 * i) += g_u / 3.0;
      grad->flow_velocity -= g_u;
    }
  }
  if (quad_hydro_) {
    const Eigen::Matrix4Xi& quads = quad_hydro_->quads;
    std::array<Vec3, 4> g_corners;
    Vec3 g_u;
    for (int q = 0; q < quads.cols(); ++q) {
      Vec3 wq = Vec3::Zero();
      for (int c = 0; c < 4; ++c) wq += w.segment<3>(3 * quads(c, q));
      wq /= 4.0;
      internal::QuadHydrodynamicForceVjp(*quad_hydro_, QuadCorners(x, quads, q),
                                         QuadRelativeVelocity(v, *quad_hydro_, q), wq, &g_corners, &g_u,
                                         &grad->quad_hydrodynamics, FaceWaterOf(wetted_quads, q));
      for (int c = 0; c < 4; ++c) {
        gx->segment<3>(3 * quads(c, q)) += g_corners[c];
        gv->segment<3>(3 * quads(c, q)) -= g_u / 4.0;
      }
      grad->quad_hydrodynamics.flow_velocity += g_u;
    }
  }
  if (!friction_.empty() && static_cast<int>(grad->penalty_friction.size()) != num_penalty_contacts_)
    grad->penalty_friction.assign(num_penalty_contacts_, 0.0);
  for (const FrictionNode& fn : friction_) {
    const double gap = fn.normal.dot(x.segment<3>(3 * fn.node)) - fn.offset;
    if (gap >= 0) continue;
    const Vec3 wi = w.segment<3>(3 * fn.node);
    const Vec3 vi = v.segment<3>(3 * fn.node);
    const Vec3 vt = vi - fn.normal.dot(vi) * fn.normal;
    const double s = std::sqrt(vt.squaredNorm() + fn.eps * fn.eps);
    const double wvt = wi.dot(vt);
    const double fn_mag = -fn.stiffness * gap;  // f_n
    // f = -mu f_n vt / s.
    gx->segment<3>(3 * fn.node) += (fn.mu * fn.stiffness * wvt / s) * fn.normal;
    const Vec3 pw = wi - fn.normal.dot(wi) * fn.normal;
    gv->segment<3>(3 * fn.node) -= fn.mu * fn_mag * (pw / s - (wvt / (s * s * s)) * vt);
    grad->penalty_friction[fn.contact] -= fn_mag * wvt / s;
  }
}

void StateForces::AddJvp(const VectorXd& x, const VectorXd& v, const VectorXd& mass,
                         const std::vector<char>& wetted_quads, const MatrixXd& dx, const MatrixXd& dv,
                         const std::vector<VectorXd>& dmass, const std::vector<StateForceGradient>& dtheta,
                         MatrixXd* df) const {
  if (empty()) return;
  const int dirs = static_cast<int>(df->cols());
  auto mass_direction = [&](int p) -> const VectorXd* {
    return p < static_cast<int>(dmass.size()) && dmass[p].size() ? &dmass[p] : nullptr;
  };
  if (damping_) {
    // F = -c M v.
    for (int p = 0; p < dirs; ++p) {
      auto col = df->col(p);
      col -= *damping_ * mass.cwiseProduct(dv.col(p));
      if (const VectorXd* dm = mass_direction(p)) col -= *damping_ * dm->cwiseProduct(v);
      if (dtheta[p].linear_damping != 0) col -= dtheta[p].linear_damping * mass.cwiseProduct(v);
    }
  }
  if (hydro_) {
    const Eigen::Matrix3Xi& tri = hydro_->triangles;
    // Per direction: the parameter components (fluid density, drag
    // tangential, drag normal, thrust) and the flow velocity's.
    Eigen::Matrix4Xd dparam(4, dirs);
    Eigen::Matrix3Xd dflow(3, dirs);
    for (int p = 0; p < dirs; ++p) {
      dparam.col(p) << dtheta[p].fluid_density, dtheta[p].drag_tangential, dtheta[p].drag_normal, dtheta[p].thrust;
      dflow.col(p) = dtheta[p].flow_velocity;
    }
    for (int t = 0; t < tri.cols(); ++t) {
      const int a = tri(0, t), b = tri(1, t), c = tri(2, t);
      const Vec3 u = MeanVelocity(v, a, b, c) - hydro_->flow_velocity;
      const Vec3 xa = x.segment<3>(3 * a);
      const Vec3 e1 = x.segment<3>(3 * b) - xa, e2 = x.segment<3>(3 * c) - xa;
      const Vec3 area = 0.5 * e1.cross(e2);
      // The 3 x 3 Jacobians dF/dN, dF/du and the 3 x 4 parameter Jacobian,
      // row by row from the vector-Jacobian products with the unit vectors.
      Mat3 d_area, d_u;
      Eigen::Matrix<double, 3, 4> d_param;
      for (int k = 0; k < 3; ++k) {
        Vec3 g_area, g_u;
        StateForceGradient g;
        HydrodynamicForceVjp(*hydro_, area, u, Vec3::Unit(k), &g_area, &g_u, &g);
        d_area.row(k) = g_area.transpose();
        d_u.row(k) = g_u.transpose();
        d_param.row(k) << g.fluid_density, g.drag_tangential, g.drag_normal, g.thrust;
      }
      if (d_area.isZero(0) && d_u.isZero(0) && d_param.isZero(0)) continue;
      for (int p = 0; p < dirs; ++p) {
        const Vec3 dxa = dx.col(p).segment<3>(3 * a);
        const Vec3 de1 = dx.col(p).segment<3>(3 * b) - dxa, de2 = dx.col(p).segment<3>(3 * c) - dxa;
        const Vec3 dn = 0.5 * (de1.cross(e2) + e1.cross(de2));
        const Vec3 du = MeanVelocity(dv.col(p), a, b, c) - dflow.col(p);
        const Vec3 share = (d_area * dn + d_u * du + d_param * dparam.col(p)) / 3.0;
        df->col(p).segment<3>(3 * a) += share;
        df->col(p).segment<3>(3 * b) += share;
        df->col(p).segment<3>(3 * c) += share;
      }
    }
  }
  if (quad_hydro_) {
    const Eigen::Matrix4Xi& quads = quad_hydro_->quads;
    for (int q = 0; q < quads.cols(); ++q) {
      const std::array<Vec3, 4> corners = QuadCorners(x, quads, q);
      const Vec3 u = QuadRelativeVelocity(v, *quad_hydro_, q);
      // The face force's Jacobians with respect to its corners (3 x 12), the
      // relative velocity (3 x 3) and the parameters (fluid density, the
      // drag and the thrust curve's control values: 3 x 9), row by row from
      // the vector-Jacobian products with the unit vectors.
      Eigen::Matrix<double, 3, 12> d_corners;
      Mat3 d_u;
      Eigen::Matrix<double, 3, 9> d_param;
      for (int k = 0; k < 3; ++k) {
        std::array<Vec3, 4> g_corners;
        Vec3 g_u;
        QuadHydrodynamicsGradient g;
        internal::QuadHydrodynamicForceVjp(*quad_hydro_, corners, u, Vec3::Unit(k), &g_corners, &g_u, &g,
                                           FaceWaterOf(wetted_quads, q));
        for (int c = 0; c < 4; ++c) d_corners.block<1, 3>(k, 3 * c) = g_corners[c].transpose();
        d_u.row(k) = g_u.transpose();
        d_param(k, 0) = g.fluid_density;
        d_param.block<1, 4>(k, 1) = g.drag_curve.transpose();
        d_param.block<1, 4>(k, 5) = g.thrust_curve.transpose();
      }
      if (d_corners.isZero(0) && d_u.isZero(0) && d_param.isZero(0)) continue;  // a face the water does not meet
      for (int p = 0; p < dirs; ++p) {
        Eigen::Matrix<double, 12, 1> dcorners;
        Vec3 dmean = Vec3::Zero();
        for (int c = 0; c < 4; ++c) {
          dcorners.segment<3>(3 * c) = dx.col(p).segment<3>(3 * quads(c, q));
          dmean += dv.col(p).segment<3>(3 * quads(c, q));
        }
        const QuadHydrodynamicsGradient& dq = dtheta[p].quad_hydrodynamics;
        Eigen::Matrix<double, 9, 1> dparam;
        dparam << dq.fluid_density, dq.drag_curve, dq.thrust_curve;
        // u = flow - mean corner velocity.
        const Vec3 du = dq.flow_velocity - dmean / 4.0;
        const Vec3 share = (d_corners * dcorners + d_u * du + d_param * dparam) / 4.0;
        for (int c = 0; c < 4; ++c) df->col(p).segment<3>(3 * quads(c, q)) += share;
      }
    }
  }
  for (const FrictionNode& fn : friction_) {
    const double gap = fn.normal.dot(x.segment<3>(3 * fn.node)) - fn.offset;
    if (gap >= 0) continue;
    // f = mu k gap vt / s, vt = P v, s = sqrt(|vt|^2 + eps^2).
    const Vec3 vi = v.segment<3>(3 * fn.node);
    const Vec3 vt = vi - fn.normal.dot(vi) * fn.normal;
    const double s = std::sqrt(vt.squaredNorm() + fn.eps * fn.eps);
    for (int p = 0; p < dirs; ++p) {
      const double dgap = fn.normal.dot(dx.col(p).segment<3>(3 * fn.node));
      const Vec3 dvi = dv.col(p).segment<3>(3 * fn.node);
      const Vec3 dvt = dvi - fn.normal.dot(dvi) * fn.normal;
      const Vec3 dvt_over_s = dvt / s - (vt.dot(dvt) / (s * s * s)) * vt;
      const std::vector<double>& dmu = dtheta[p].penalty_friction;
      const double dmu_c = fn.contact < static_cast<int>(dmu.size()) ? dmu[fn.contact] : 0.0;
      df->col(p).segment<3>(3 * fn.node) +=
          fn.stiffness * ((fn.mu * dgap + dmu_c * gap) / s * vt + fn.mu * gap * dvt_over_s);
    }
  }
}

}  // namespace diffpd::internal
