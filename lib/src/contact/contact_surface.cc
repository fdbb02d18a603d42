// Collision surfaces of frictional contact: gap, projection and its Jacobian.
#include <cmath>

#include "diffpd/contact.h"

namespace diffpd {

ContactSurface ContactSurface::Plane(const Vec3& normal, double offset) {
  ContactSurface s;
  s.kind = Kind::kPlane;
  s.normal = normal;
  s.offset = offset;
  return s;
}

ContactSurface ContactSurface::Sphere(const Vec3& center, double radius) {
  ContactSurface s;
  s.kind = Kind::kSphere;
  s.center = center;
  s.radius = radius;
  return s;
}

ContactSurface ContactSurface::HeightField(std::function<double(double, double)> height,
                                           std::function<Eigen::Vector2d(double, double)> height_gradient) {
  ContactSurface s;
  s.kind = Kind::kHeightField;
  s.height = std::move(height);
  s.height_gradient = std::move(height_gradient);
  return s;
}

double ContactSurface::Gap(const Vec3& x) const {
  switch (kind) {
    case Kind::kPlane:
      return normal.normalized().dot(x) - offset;
    case Kind::kSphere:
      return (x - center).norm() - radius;
    case Kind::kHeightField:
      return x(2) - height(x(0), x(1));
  }
  return 0;
}

Vec3 ContactSurface::GapGradient(const Vec3& x) const {
  switch (kind) {
    case Kind::kPlane:
      return normal.normalized();
    case Kind::kSphere: {
      const Vec3 d = x - center;
      const double r = d.norm();
      return r > 0 ? Vec3(d / r) : Vec3(0, 0, 1);
    }
    case Kind::kHeightField: {
      const Eigen::Vector2d g = height_gradient(x(0), x(1));
      return Vec3(-g(0), -g(1), 1.0);
    }
  }
  return Vec3::Zero();
}

Vec3 ContactSurface::Project(const Vec3& x) const {
  switch (kind) {
    case Kind::kPlane: {
      const Vec3 n = normal.normalized();
      return x - (n.dot(x) - offset) * n;
    }
    case Kind::kSphere:
      return center + radius * GapGradient(x);
    case Kind::kHeightField:
      return Vec3(x(0), x(1), height(x(0), x(1)));
  }
  return x;
}

Mat3 ContactSurface::ProjectJacobian(const Vec3& x) const {
  switch (kind) {
    case Kind::kPlane: {
      const Vec3 n = normal.normalized();
      return Mat3::Identity() - n * n.transpose();
    }
    case Kind::kSphere: {
      const Vec3 d = x - center;
      const double r = d.norm();
      if (r == 0) return Mat3::Zero();
      const Vec3 u = d / r;
      return (radius / r) * (Mat3::Identity() - u * u.transpose());
    }
    case Kind::kHeightField: {
      const Eigen::Vector2d g = height_gradient(x(0), x(1));
      Mat3 j = Mat3::Zero();
      j(0, 0) = 1;
      j(1, 1) = 1;
      j(2, 0) = g(0);
      j(2, 1) = g(1);
      return j;
    }
  }
  return Mat3::Identity();
}

}  // namespace diffpd
