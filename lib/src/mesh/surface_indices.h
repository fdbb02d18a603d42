// Index check shared by the functions that consume a SurfaceMesh (internal).
#pragma once

#include <sstream>
#include <string>

#include "diffpd/error.h"
#include "diffpd/surface_mesh.h"

namespace diffpd::internal {

// Throws InvalidInputError "<function>: the surface has no triangles" or
// "<function>: triangle 4 references vertex 99, but the surface has 50 vertices".
inline void CheckTriangleIndices(const SurfaceMesh& surface, const std::string& function) {
  if (surface.triangles.cols() == 0) throw InvalidInputError(function + ": the surface has no triangles");
  const long n = surface.vertices.cols();
  for (int t = 0; t < surface.triangles.cols(); ++t) {
    for (int c = 0; c < 3; ++c) {
      if (surface.triangles(c, t) < 0 || surface.triangles(c, t) >= n) {
        std::ostringstream s;
        s << function << ": triangle " << t << " references vertex " << surface.triangles(c, t)
          << ", but the surface has " << n << " vertices";
        throw InvalidInputError(s.str());
      }
    }
  }
}

}  // namespace diffpd::internal
