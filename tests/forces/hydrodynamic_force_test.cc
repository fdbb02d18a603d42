// Drag and thrust on one triangle: the documented limits of the model
// (Cd = drag_tangential along the face, drag_normal across it; thrust normal
// to the face and opposing its motion; no force and no derivative at rest),
// dissipation, and the vector-Jacobian products vs finite differences.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Geometry>

#include "forces/hydrodynamic_force.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

Hydrodynamics Params() {
  Hydrodynamics p;
  p.fluid_density = 1000;
  p.drag_tangential = 0.05;
  p.drag_normal = 2.05;
  p.thrust = 0.7;
  return p;
}

TEST(HydrodynamicForceTest, DragCoefficientRisesFromTangentialToNormalFlow) {
  Hydrodynamics p = Params();
  p.thrust = 0;
  const Vec3 area_vector(0, 0, 0.02);  // A = 0.02 m^2, n = z
  const double speed = 0.3;
  const double q = 0.5 * p.fluid_density * 0.02 * speed * speed;
  const Vec3 along = internal::HydrodynamicForce(p, area_vector, Vec3(speed, 0, 0));
  const Vec3 across = internal::HydrodynamicForce(p, area_vector, Vec3(0, 0, speed));
  EXPECT_LT((along - Vec3(-q * 0.05, 0, 0)).norm(), 1e-12);
  EXPECT_LT((across - Vec3(0, 0, -q * 2.05)).norm(), 1e-12);
  // 45 degrees: Cd = 0.05 + 2.0 / 2, along -u.
  const Vec3 u = speed * Vec3(1, 0, 1).normalized();
  EXPECT_LT((internal::HydrodynamicForce(p, area_vector, u) + q * 1.05 * u / speed).norm(), 1e-12);
}

TEST(HydrodynamicForceTest, ThrustIsNormalAndOpposesTheNormalMotion) {
  Hydrodynamics p = Params();
  p.drag_tangential = p.drag_normal = 0;
  const Vec3 area_vector = 0.01 * Vec3(1, 2, 2) / 3.0;  // A = 0.01
  const Vec3 u(0.2, -0.1, 0.4);
  const Vec3 f = internal::HydrodynamicForce(p, area_vector, u);
  const Vec3 n = area_vector.normalized();
  EXPECT_LT(f.cross(n).norm(), 1e-14);
  EXPECT_LT(f.dot(n) * n.dot(u), 0.0);
  EXPECT_NEAR(f.norm(), 0.5 * p.fluid_density * 0.01 * 0.7 * std::abs(n.dot(u)) * u.norm(), 1e-12);
}

TEST(HydrodynamicForceTest, ForceAndDerivativesVanishAtRestAndForcesDissipate) {
  const Hydrodynamics p = Params();
  const Vec3 area_vector(0.01, 0.0, 0.005);
  EXPECT_EQ(internal::HydrodynamicForce(p, area_vector, Vec3::Zero()).norm(), 0.0);
  Vec3 ga, gu;
  StateForceGradient grad;
  internal::HydrodynamicForceVjp(p, area_vector, Vec3::Zero(), Vec3(1, 2, 3), &ga, &gu, &grad);
  EXPECT_EQ(ga.norm() + gu.norm(), 0.0);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal;
  for (int t = 0; t < 20; ++t) {
    const Vec3 u(normal(rng), normal(rng), normal(rng));
    EXPECT_LT(internal::HydrodynamicForce(p, area_vector, u).dot(u), 0.0);
  }
}

TEST(HydrodynamicForceTest, VectorJacobianProductsMatchFiniteDifferences) {
  std::mt19937_64 rng(2);
  std::normal_distribution<double> normal;
  auto random3 = [&] { return Vec3(normal(rng), normal(rng), normal(rng)); };
  for (int t = 0; t < 10; ++t) {
    Hydrodynamics p = Params();
    const Vec3 n = 0.01 * random3(), u = random3(), w = random3();
    Vec3 ga, gu;
    StateForceGradient grad;
    internal::HydrodynamicForceVjp(p, n, u, w, &ga, &gu, &grad);
    const auto wf_u = [&](const VectorXd& uu) { return w.dot(internal::HydrodynamicForce(p, n, uu)); };
    const auto wf_n = [&](const VectorXd& nn) { return w.dot(internal::HydrodynamicForce(p, nn, u)); };
    EXPECT_TRUE(testing::Passes(testing::CheckGradient(wf_u, u, gu))) << "u";
    EXPECT_TRUE(testing::Passes(testing::CheckGradient(wf_n, n, ga))) << "area vector";
    auto check_param = [&](double* field, double analytic) {
      // F is linear in every parameter: a large step has no truncation error
      // and keeps rounding at 1e-12 relative, so the test's own step and
      // tolerance stay (1e-9 relative, 1e-14 absolute).
      const double saved = *field;
      const auto wf_param = [&](const VectorXd& value) {
        *field = value(0);
        const double result = w.dot(internal::HydrodynamicForce(p, n, u));
        *field = saved;
        return result;
      };
      testing::DifferenceOptions options;
      options.step = 1e-3 * std::max(1.0, std::abs(saved));
      options.rtol = 1e-9;
      options.floor = 1e-14;
      EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(wf_param, VectorXd::Constant(1, saved),
                                                                      VectorXd::Ones(1), analytic, options)));
    };
    check_param(&p.fluid_density, grad.fluid_density);
    check_param(&p.drag_tangential, grad.drag_tangential);
    check_param(&p.drag_normal, grad.drag_normal);
    check_param(&p.thrust, grad.thrust);
  }
}

}  // namespace
}  // namespace diffpd
