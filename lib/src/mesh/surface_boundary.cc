#include "mesh/surface_boundary.h"

#include <algorithm>
#include <vector>

#include "diffpd/error.h"

namespace diffpd::internal {

SurfaceBoundary FindSurfaceBoundary(const SurfaceMesh& surface) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * surface.triangles.cols());
  for (Eigen::Index t = 0; t < surface.triangles.cols(); ++t)
    for (int c = 0; c < 3; ++c) {
      const int a = surface.triangles(c, t), b = surface.triangles((c + 1) % 3, t);
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  SurfaceBoundary boundary;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if ((j - i) % 2 == 1) {
      if (boundary.num_edges == 0) boundary.first_edge = edges[i];
      ++boundary.num_edges;
    }
    i = j;
  }
  return boundary;
}

void CheckClosed(const SurfaceMesh& surface, const std::string& function) {
  const SurfaceBoundary boundary = FindSurfaceBoundary(surface);
  if (boundary.num_edges == 0) return;
  throw InvalidInputError(function + ": the surface is not closed: " + std::to_string(boundary.num_edges) +
                          " boundary edges, the first (" + std::to_string(boundary.first_edge.first) + ", " +
                          std::to_string(boundary.first_edge.second) +
                          ") (a closed surface has every edge in an even number of triangles)");
}

}  // namespace diffpd::internal
