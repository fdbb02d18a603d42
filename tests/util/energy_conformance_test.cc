// The conformance check itself, on small terms written here: a correct
// spring network, drag force and sphere projection conform; each planted
// defect (a wrong gradient, a Hessian without its geometric part, an energy
// that is not frame indifferent, a wrong vector-Jacobian product, a wrong
// projection differential, a projection that is not idempotent) fails exactly
// the property it breaks.
#include "util/energy_conformance.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

namespace diffpd::testing {
namespace {

// Springs between the 4 corners of a tetrahedron, rest lengths those of
// `rest`: E = sum (k/2)(|x_i - x_j| - L_ij)^2.
constexpr double kRestCorners[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
struct Springs {
  VectorXd rest = Eigen::Map<const Eigen::Matrix<double, 12, 1>>(kRestCorners);
  double k = 3.0;
  template <class Visit>
  void ForEach(const VectorXd& x, Visit&& visit) const {
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const Vec3 r = x.segment<3>(3 * i) - x.segment<3>(3 * j);
        visit(i, j, r, (rest.segment<3>(3 * i) - rest.segment<3>(3 * j)).norm());
      }
  }
  double Energy(const VectorXd& x) const {
    double e = 0;
    ForEach(x, [&](int, int, const Vec3& r, double l) { e += 0.5 * k * (r.norm() - l) * (r.norm() - l); });
    return e;
  }
  VectorXd Gradient(const VectorXd& x) const {
    VectorXd g = VectorXd::Zero(12);
    ForEach(x, [&](int i, int j, const Vec3& r, double l) {
      const Vec3 f = k * (r.norm() - l) * r.normalized();
      g.segment<3>(3 * i) += f;
      g.segment<3>(3 * j) -= f;
    });
    return g;
  }
  VectorXd HessianProduct(const VectorXd& x, const VectorXd& z, bool geometric = true) const {
    VectorXd out = VectorXd::Zero(12);
    ForEach(x, [&](int i, int j, const Vec3& r, double l) {
      const Vec3 u = r.normalized();
      Mat3 h = k * u * u.transpose();
      if (geometric) h += k * (1 - l / r.norm()) * (Mat3::Identity() - u * u.transpose());
      const Vec3 dz = z.segment<3>(3 * i) - z.segment<3>(3 * j);
      out.segment<3>(3 * i) += h * dz;
      out.segment<3>(3 * j) -= h * dz;
    });
    return out;
  }
};

Symmetry FrameRotation() { return Symmetry{"frame rotation", RotateEach3, {}, {}}; }

EnergyTerm SpringTerm() {
  static const Springs s;
  EnergyTerm t;
  t.name = "springs";
  t.energy = [](const VectorXd& x) { return s.Energy(x); };
  t.gradient = [](const VectorXd& x) { return s.Gradient(x); };
  t.hessian_product = [](const VectorXd& x, const VectorXd& z) { return s.HessianProduct(x, z); };
  t.random_state = [](std::mt19937_64* rng) {
    std::normal_distribution<double> normal(0.0, 0.1);
    VectorXd x = s.rest;
    for (int i = 0; i < 12; ++i) x(i) += normal(*rng);
    return x;
  };
  t.rest = s.rest;
  t.symmetries = {FrameRotation()};
  return t;
}

// The names of the failed properties, without " at state N".
std::set<std::string> Failed(const ConformanceResult& r) {
  std::set<std::string> names;
  for (const ConformanceProperty& p : r.properties)
    if (!p.passed) names.insert(p.name.substr(0, p.name.find(" at state")));
  return names;
}

TEST(EnergyConformanceTest, ACorrectEnergyConformsAndEveryPropertyIsChecked) {
  const ConformanceResult r = CheckEnergyConformance(SpringTerm());
  EXPECT_TRUE(Conforms(r)) << r.Describe(true);
  std::set<std::string> checked;
  for (const ConformanceProperty& p : r.properties) checked.insert(p.name.substr(0, p.name.find(" at state")));
  EXPECT_EQ(checked, (std::set<std::string>{
                         "zero energy at rest", "zero gradient at rest", "invariance under frame rotation",
                         "gradient covariance under frame rotation", "gradient", "Hessian", "Hessian symmetry"}));
  // 12 entries: whole Jacobians at each of the 4 states.
  EXPECT_EQ(r.properties.size(), 2u + 4u * 5u);
  EXPECT_GT(r.min_margin(), 10.0);
}

TEST(EnergyConformanceTest, AWrongGradientFails) {
  EnergyTerm t = SpringTerm();
  const auto right = t.gradient;
  // One spring's force 0.1% too large, as a mistyped constant would make it.
  t.gradient = [right](const VectorXd& x) {
    VectorXd g = right(x);
    g.segment<3>(0) *= 1.001;
    return g;
  };
  const ConformanceResult r = CheckEnergyConformance(t);
  EXPECT_FALSE(r.passed());
  EXPECT_EQ(Failed(r).count("gradient"), 1u) << r.Describe();
  EXPECT_EQ(Failed(r).count("Hessian symmetry"), 0u);
  EXPECT_FALSE(Conforms(r));
}

TEST(EnergyConformanceTest, AHessianWithoutItsGeometricPartFails) {
  EnergyTerm t = SpringTerm();
  t.hessian_product = [](const VectorXd& x, const VectorXd& z) { return Springs().HessianProduct(x, z, false); };
  const ConformanceResult r = CheckEnergyConformance(t);
  EXPECT_EQ(Failed(r), std::set<std::string>{"Hessian"}) << r.Describe();
}

TEST(EnergyConformanceTest, AnEnergyThatIsNotFrameIndifferentFails) {
  EnergyTerm t = SpringTerm();
  const auto e = t.energy;
  const auto g = t.gradient;
  // Plus a spring of node 0 to a fixed point: still a correct energy with a
  // correct gradient, but not invariant under rotations of the frame.
  t.energy = [e](const VectorXd& x) { return e(x) + 0.5 * (x.segment<3>(0) - Vec3(0.1, 0, 0)).squaredNorm(); };
  t.gradient = [g](const VectorXd& x) {
    VectorXd out = g(x);
    out.segment<3>(0) += x.segment<3>(0) - Vec3(0.1, 0, 0);
    return out;
  };
  const auto h = t.hessian_product;
  t.hessian_product = [h](const VectorXd& x, const VectorXd& z) {
    VectorXd out = h(x, z);
    out.segment<3>(0) += z.segment<3>(0);
    return out;
  };
  const ConformanceResult r = CheckEnergyConformance(t);
  EXPECT_EQ(Failed(r),
            (std::set<std::string>{"zero energy at rest", "zero gradient at rest", "invariance under frame rotation",
                                   "gradient covariance under frame rotation"}))
      << r.Describe();
}

// Quadratic drag F(v) = -c |v| v per node, (dF/dv)^T w = -c (|v| w + v (v . w) / |v|).
ForceTerm DragTerm(bool wrong) {
  ForceTerm t;
  t.name = "drag";
  t.force = [](const VectorXd& v) {
    VectorXd f(v.size());
    for (int i = 0; i < v.size(); i += 3) f.segment<3>(i) = -2.0 * v.segment<3>(i).norm() * v.segment<3>(i);
    return f;
  };
  t.vjp = [wrong](const VectorXd& v, const VectorXd& w) {
    VectorXd g(v.size());
    for (int i = 0; i < v.size(); i += 3) {
      const Vec3 vi = v.segment<3>(i), wi = w.segment<3>(i);
      g.segment<3>(i) = -2.0 * (vi.norm() * wi + (wrong ? 0.0 : 1.0) * vi * vi.dot(wi) / vi.norm());
    }
    return g;
  };
  t.random_state = [](std::mt19937_64* rng) {
    std::normal_distribution<double> normal;
    VectorXd v(30);
    for (int i = 0; i < 30; ++i) v(i) = normal(*rng);
    return v;
  };
  t.rest = VectorXd::Zero(30);
  t.symmetries = {FrameRotation()};
  return t;
}

TEST(EnergyConformanceTest, ForceTermsConformAndAWrongVectorJacobianProductFails) {
  const ConformanceResult good = CheckForceConformance(DragTerm(false));
  EXPECT_TRUE(Conforms(good)) << good.Describe(true);
  const ConformanceResult bad = CheckForceConformance(DragTerm(true));
  EXPECT_EQ(Failed(bad), std::set<std::string>{"force differential"}) << bad.Describe();
}

// The sphere |p| = r: p = r f / |f|, dp/df = r (I - f^ f^^T) / |f|.
ProjectionTerm SphereTerm(bool wrong_differential, bool idempotent) {
  ProjectionTerm t;
  t.name = "sphere";
  t.project = [idempotent](const VectorXd& f) -> VectorXd {
    return f.normalized() * (idempotent ? 1.5 : 1.5 + 0.1 * f.norm());
  };
  t.differential = [wrong_differential, idempotent](const VectorXd& f, const VectorXd& z) -> VectorXd {
    const Vec3 u = f.normalized();
    const Mat3 tangent = Mat3::Identity() - (wrong_differential ? 0.0 : 1.0) * u * u.transpose();
    const double radius = idempotent ? 1.5 : 1.5 + 0.1 * f.norm();
    Vec3 out = radius / f.norm() * tangent * z;
    if (!idempotent) out += 0.1 * u * u.dot(z);
    return out;
  };
  t.random_state = [](std::mt19937_64* rng) {
    std::normal_distribution<double> normal;
    return Vec3(normal(*rng), normal(*rng), normal(*rng)).eval();
  };
  t.violation = [](const VectorXd& p) { return p.norm() - 1.5; };
  t.symmetries = {FrameRotation()};
  return t;
}

TEST(EnergyConformanceTest, ProjectionsConformAndDefectsFailTheirProperty) {
  const ConformanceResult good = CheckProjectionConformance(SphereTerm(false, true));
  EXPECT_TRUE(Conforms(good)) << good.Describe(true);
  const ConformanceResult wrong = CheckProjectionConformance(SphereTerm(true, true));
  EXPECT_EQ(Failed(wrong), std::set<std::string>{"differential"}) << wrong.Describe();
  const ConformanceResult off = CheckProjectionConformance(SphereTerm(false, false));
  EXPECT_EQ(Failed(off), (std::set<std::string>{"projection in the set", "idempotence"})) << off.Describe();
}

}  // namespace
}  // namespace diffpd::testing
