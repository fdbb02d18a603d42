// WindingNumber, EnclosedVolume and ValidateWatertight (surface_mesh.h).
#include "diffpd/surface_mesh.h"

#include <cmath>
#include <algorithm>
#include <map>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>

#include "diffpd/error.h"

namespace diffpd {
namespace {
constexpr double kPi = 3.14159265358979323846;
}  // namespace

double WindingNumber(const SurfaceMesh& surface, const Vec3& p) {
  double total = 0.0;
  for (int t = 0; t < surface.triangles.cols(); ++t) {
    const Vec3 a = surface.vertices.col(surface.triangles(0, t)) - p;
    const Vec3 b = surface.vertices.col(surface.triangles(1, t)) - p;
    const Vec3 c = surface.vertices.col(surface.triangles(2, t)) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    total += 2.0 * std::atan2(numerator, denominator);
  }
  return total / (4.0 * kPi);
}

double EnclosedVolume(const SurfaceMesh& surface) {
  double volume = 0.0;
  for (int t = 0; t < surface.triangles.cols(); ++t) {
    const Vec3 a = surface.vertices.col(surface.triangles(0, t));
    const Vec3 b = surface.vertices.col(surface.triangles(1, t));
    const Vec3 c = surface.vertices.col(surface.triangles(2, t));
    volume += a.dot(b.cross(c));
  }
  return volume / 6.0;
}

void ValidateWatertight(const SurfaceMesh& surface, const std::string& what) {
  const long n = surface.vertices.cols();
  if (surface.triangles.cols() == 0) throw InvalidInputError(what + ": the surface has no triangles");
  // Undirected edge (lo, hi) -> triangles using it and whether each uses it as lo -> hi.
  struct EdgeUse {
    int count = 0;
    int first_triangle = -1;
    bool first_forward = false;
  };
  std::map<std::pair<int, int>, EdgeUse> edges;
  for (int t = 0; t < surface.triangles.cols(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const int v = surface.triangles(c, t);
      std::ostringstream s;
      if (v < 0 || v >= n) {
        s << what << ": triangle " << t << " references vertex " << v << ", but the surface has " << n << " vertices";
        throw InvalidInputError(s.str());
      }
      if (surface.triangles((c + 1) % 3, t) == v) {
        s << what << ": triangle " << t << " repeats vertex " << v;
        throw InvalidInputError(s.str());
      }
    }
    for (int c = 0; c < 3; ++c) {
      const int u = surface.triangles(c, t), v = surface.triangles((c + 1) % 3, t);
      EdgeUse& use = edges[{std::min(u, v), std::max(u, v)}];
      const bool forward = u < v;
      if (use.count == 1 && use.first_forward == forward) {
        std::ostringstream s;
        s << what << ": edge (" << std::min(u, v) << ", " << std::max(u, v) << ") has the same direction in triangles "
          << use.first_triangle << " and " << t << " (inconsistent orientation)";
        throw InvalidInputError(s.str());
      }
      if (use.count == 0) {
        use.first_triangle = t;
        use.first_forward = forward;
      }
      ++use.count;
    }
  }
  for (const auto& [edge, use] : edges) {
    if (use.count != 2) {
      std::ostringstream s;
      s << what << ": edge (" << edge.first << ", " << edge.second << ") is used by " << use.count
        << " triangle(s); a closed surface needs exactly 2";
      throw InvalidInputError(s.str());
    }
  }
}

}  // namespace diffpd
