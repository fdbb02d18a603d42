// Collision surfaces (plane, sphere, height field): gap sign, projection onto
// the surface and its Jacobian vs finite differences; pins of contact nodes
// (the projection of the previous position) and their derivatives vs finite
// differences.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "contact/active_set_step.h"
#include "diffpd/contact.h"

namespace diffpd {
namespace {

std::vector<ContactSurface> Surfaces() {
  return {ContactSurface::Plane(Vec3(0.2, -0.1, 1.0), 0.03), ContactSurface::Sphere(Vec3(0.1, 0.0, -0.5), 0.5),
          ContactSurface::HeightField(
              [](double x, double y) { return 0.02 * std::sin(5 * x) + 0.01 * x * y; },
              [](double x, double y) { return Eigen::Vector2d(0.1 * std::cos(5 * x) + 0.01 * y, 0.01 * x); })};
}

TEST(ContactSurfaceTest, ProjectionLiesOnTheSurfaceAndItsJacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  for (const ContactSurface& s : Surfaces()) {
    for (int t = 0; t < 5; ++t) {
      const Vec3 x(u(rng), u(rng), 0.02 + u(rng));
      EXPECT_NEAR(s.Gap(s.Project(x)), 0.0, 1e-14);
      const Mat3 j = s.ProjectJacobian(x);
      for (int d = 0; d < 3; ++d) {
        const double eps = 1e-6;
        const Vec3 fd = (s.Project(x + eps * Vec3::Unit(d)) - s.Project(x - eps * Vec3::Unit(d))) / (2 * eps);
        EXPECT_LT((fd - j.col(d)).norm(), 1e-8);
        const double gfd = (s.Gap(x + eps * Vec3::Unit(d)) - s.Gap(x - eps * Vec3::Unit(d))) / (2 * eps);
        EXPECT_NEAR(gfd, s.GapGradient(x)(d), 1e-8);
      }
    }
  }
  // Gap sign: the plane's outside is along its normal; the sphere is an obstacle.
  EXPECT_GT(Surfaces()[0].Gap(Vec3(0, 0, 1)), 0.0);
  EXPECT_LT(Surfaces()[1].Gap(Vec3(0.1, 0, -0.4)), 0.0);
  EXPECT_LT(Surfaces()[2].Gap(Vec3(0, 0, -0.01)), 0.0);
}

TEST(ContactPinTest, NodeIsPinnedAtTheProjectionOfItsPreviousPosition) {
  const ContactSurface plane = ContactSurface::Plane(Vec3(0, 0, 1), 0.0);
  // Arriving from above, resting, or pulled inside: straight onto the plane.
  EXPECT_LT((internal::ComputeContactPin(plane, Vec3(0.1, 0, 0.002), Vec3(1, 0, -0.4), 0.01).position - Vec3(0.1, 0, 0))
                .norm(),
            1e-15);
  EXPECT_LT((internal::ComputeContactPin(plane, Vec3(0.3, 0.1, 0), Vec3(0.5, 0, 0), 0.01).position - Vec3(0.3, 0.1, 0))
                .norm(),
            1e-15);
  EXPECT_LT(
      (internal::ComputeContactPin(plane, Vec3(0.3, 0.1, -0.001), Vec3(0, 0, -1), 0.01).position - Vec3(0.3, 0.1, 0))
          .norm(),
      1e-15);
}

TEST(ContactPinTest, PinDerivativesMatchFiniteDifferencesOnEverySurface) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (const ContactSurface& s : Surfaces()) {
    for (const double height : {0.003, 0.0, -0.001}) {
      const Vec3 base(u(rng), u(rng), 0);
      const Vec3 on = s.Project(base);
      const Vec3 x = on + height * s.GapGradient(on).normalized() + Vec3(0.001, -0.002, 0);
      const Vec3 v(0.3, 0.2, -0.6);
      const internal::ContactPin pin = internal::ComputeContactPin(s, x, v, 0.01);
      EXPECT_NEAR(s.Gap(pin.position), 0.0, 1e-13);
      EXPECT_EQ(pin.d_dv.norm(), 0.0);
      for (int d = 0; d < 3; ++d) {
        const double eps = 1e-7;
        const Vec3 e = Vec3::Unit(d);
        const Vec3 fdx = (internal::ComputeContactPin(s, x + eps * e, v, 0.01).position -
                          internal::ComputeContactPin(s, x - eps * e, v, 0.01).position) /
                         (2 * eps);
        EXPECT_LT((fdx - pin.d_dx.col(d)).norm(), 1e-7);
      }
    }
  }
}

}  // namespace
}  // namespace diffpd
