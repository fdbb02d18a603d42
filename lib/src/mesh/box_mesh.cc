#include "diffpd/box_mesh.h"

#include <cmath>
#include <sstream>
#include <vector>

#include "diffpd/error.h"
#include "mesh/hex_grid.h"

namespace diffpd {

Mesh MakeBoxHexMesh(const Eigen::Vector3i& cells, const Vec3& size, const Vec3& origin) {
  for (int d = 0; d < 3; ++d) {
    std::ostringstream s;
    if (cells(d) < 1) {
      s << "MakeBoxHexMesh: cells(" << d << ") = " << cells(d) << ", must be >= 1";
      throw InvalidInputError(s.str());
    }
    if (!(size(d) > 0.0) || !std::isfinite(size(d))) {
      s << "MakeBoxHexMesh: size(" << d << ") = " << size(d) << " m, must be finite and > 0";
      throw InvalidInputError(s.str());
    }
    if (!std::isfinite(origin(d))) {
      s << "MakeBoxHexMesh: origin(" << d << ") = " << origin(d) << " m, must be finite";
      throw InvalidInputError(s.str());
    }
  }
  internal::CheckGridSize("MakeBoxHexMesh", cells.cast<double>());
  const internal::HexGrid grid{origin, cells, size.cwiseQuotient(cells.cast<double>())};
  return internal::MeshFromCells(grid, std::vector<bool>(grid.num_cells(), true));
}

}  // namespace diffpd
