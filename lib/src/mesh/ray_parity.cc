#include "mesh/ray_parity.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace diffpd::internal {
namespace {

using Vec2 = Eigen::Vector2d;

// cross(b - a, q - a), evaluated from the lexicographically smaller endpoint
// so that EdgeFunction(a, b, q) == -EdgeFunction(b, a, q) exactly.
double EdgeFunction(const Vec2& a, const Vec2& b, const Vec2& q) {
  const bool a_first = a(0) < b(0) || (a(0) == b(0) && a(1) < b(1));
  const Vec2& p0 = a_first ? a : b;
  const Vec2& p1 = a_first ? b : a;
  const double value = (p1(0) - p0(0)) * (q(1) - p0(1)) - (p1(1) - p0(1)) * (q(0) - p0(0));
  return a_first ? value : -value;
}

// Whether a point on the (counterclockwise) directed edge a -> b belongs to
// the triangle on its left: the "top-left" rule.
bool OwnsEdge(const Vec2& a, const Vec2& b) {
  const Vec2 dir = b - a;
  return dir(1) > 0.0 || (dir(1) == 0.0 && dir(0) < 0.0);
}

// Adds to `crossings` (one list per column (cu, cv), index cu * n_v + cv)
// the coordinates along axis d where the column rays cross each triangle.
void CollectCrossings(const SurfaceMesh& surface, const HexGrid& grid, int d,
                      std::vector<std::vector<double>>* crossings) {
  const int u = (d + 1) % 3, v = (d + 2) % 3;
  const int nu = grid.cells(u), nv = grid.cells(v);
  for (int t = 0; t < surface.triangles.cols(); ++t) {
    Eigen::Vector3d x[3];
    Vec2 p[3];
    for (int c = 0; c < 3; ++c) {
      x[c] = surface.vertices.col(surface.triangles(c, t));
      p[c] = Vec2(x[c](u), x[c](v));
    }
    const double area = EdgeFunction(p[0], p[1], p[2]);
    if (area == 0.0) continue;
    const double sign = area > 0.0 ? 1.0 : -1.0;
    const Vec2 lo = p[0].cwiseMin(p[1]).cwiseMin(p[2]);
    const Vec2 hi = p[0].cwiseMax(p[1]).cwiseMax(p[2]);
    // Column index range whose centres fall inside the projected bounding box.
    const auto first = [&](double x, int axis) {
      return static_cast<int>(std::max(0.0, std::ceil((x - grid.origin(axis)) / grid.spacing(axis) - 0.5)));
    };
    const auto last = [&](double x, int axis, int n) {
      return static_cast<int>(std::min(n - 1.0, std::floor((x - grid.origin(axis)) / grid.spacing(axis) - 0.5)));
    };
    const int cu0 = first(lo(0), u), cu1 = last(hi(0), u, nu);
    const int cv0 = first(lo(1), v), cv1 = last(hi(1), v, nv);
    for (int cu = cu0; cu <= cu1; ++cu) {
      for (int cv = cv0; cv <= cv1; ++cv) {
        const Vec2 q(grid.origin(u) + (cu + 0.5) * grid.spacing(u), grid.origin(v) + (cv + 0.5) * grid.spacing(v));
        double w[3];  // w[c]: edge opposite corner c, scaled to be positive inside
        bool inside = true;
        for (int c = 0; c < 3 && inside; ++c) {
          const Vec2& a = p[(c + 1) % 3];
          const Vec2& b = p[(c + 2) % 3];
          w[c] = sign * EdgeFunction(a, b, q);
          if (w[c] < 0.0) inside = false;
          if (w[c] == 0.0) inside = sign > 0.0 ? OwnsEdge(a, b) : OwnsEdge(b, a);
        }
        if (!inside) continue;
        const double total = w[0] + w[1] + w[2];
        const double coordinate = (w[0] * x[0](d) + w[1] * x[1](d) + w[2] * x[2](d)) / total;
        (*crossings)[static_cast<size_t>(cu) * nv + cv].push_back(coordinate);
      }
    }
  }
}

}  // namespace

std::vector<bool> InsideByRayParity(const SurfaceMesh& surface, const HexGrid& grid) {
  std::vector<unsigned char> votes(grid.num_cells(), 0);
  for (int d = 0; d < 3; ++d) {
    const int u = (d + 1) % 3, v = (d + 2) % 3;
    std::vector<std::vector<double>> crossings(static_cast<size_t>(grid.cells(u)) * grid.cells(v));
    CollectCrossings(surface, grid, d, &crossings);
    for (int cu = 0; cu < grid.cells(u); ++cu) {
      for (int cv = 0; cv < grid.cells(v); ++cv) {
        std::vector<double>& column = crossings[static_cast<size_t>(cu) * grid.cells(v) + cv];
        std::sort(column.begin(), column.end());
        size_t below = 0;
        for (int cd = 0; cd < grid.cells(d); ++cd) {
          const double centre = grid.origin(d) + (cd + 0.5) * grid.spacing(d);
          while (below < column.size() && column[below] < centre) ++below;
          if (below % 2 == 0) continue;
          int index[3];
          index[d] = cd;
          index[u] = cu;
          index[v] = cv;
          ++votes[grid.CellIndex(index[0], index[1], index[2])];
        }
      }
    }
  }
  std::vector<bool> inside(votes.size());
  for (size_t c = 0; c < votes.size(); ++c) inside[c] = votes[c] >= 2;
  return inside;
}

}  // namespace diffpd::internal
