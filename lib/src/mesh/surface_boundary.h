// The boundary of a triangle surface, for the functions that need a closed
// one (internal).
#pragma once

#include <string>
#include <utility>

#include "diffpd/surface_mesh.h"

namespace diffpd::internal {

// The surface's boundary edges: edges used by an odd number of triangles
// (the boundary modulo 2). A closed surface has none, whether it is a
// manifold (every edge in 2 triangles) or touches itself along edges (in 4,
// ...): then the parity of a ray's crossings tells inside from outside.
struct SurfaceBoundary {
  long num_edges = 0;
  std::pair<int, int> first_edge{-1, -1};  // the smallest (lo, hi) boundary edge, if any
};
// Triangle indices must be in range (CheckTriangleIndices).
SurfaceBoundary FindSurfaceBoundary(const SurfaceMesh& surface);

// Throws InvalidInputError unless the surface is closed:
//   "<function>: the surface is not closed: 12 boundary edges, the first (3, 7) (a closed surface has every edge in
//   an even number of triangles)".
void CheckClosed(const SurfaceMesh& surface, const std::string& function);

}  // namespace diffpd::internal
