#include "mesh/hex_grid.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {

void CheckGridSize(const std::string& function, const Eigen::Vector3d& cells, const std::string& detail) {
  const double total = cells.prod();
  if (total <= kMaxGridCells) return;
  std::ostringstream s;
  s << function << ": cells = (" << cells(0) << ", " << cells(1) << ", " << cells(2) << ") is " << total
    << " cells, more than the limit of " << kMaxGridCells << detail;
  throw InvalidInputError(s.str());
}

Mesh MeshFromCells(const HexGrid& grid, const std::vector<bool>& keep) {
  DIFFPD_CHECK(static_cast<long>(keep.size()) == grid.num_cells(),
               "keep has " << keep.size() << " entries for " << grid.num_cells() << " cells");
  const int nx = grid.cells(0), ny = grid.cells(1), nz = grid.cells(2);
  const long num_points = static_cast<long>(nx + 1) * (ny + 1) * (nz + 1);
  std::vector<int> vertex_of_point(num_points, -1);
  long num_kept = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        if (!keep[grid.CellIndex(i, j, k)]) continue;
        ++num_kept;
        for (int a = 0; a < 8; ++a) {
          vertex_of_point[grid.PointIndex(i + (a >> 2 & 1), j + (a >> 1 & 1), k + (a & 1))] = 0;
        }
      }
  int num_vertices = 0;
  for (int& v : vertex_of_point) {
    if (v == 0) v = num_vertices++;
  }
  Mesh mesh;
  mesh.type = ElementType::kHex8;
  mesh.vertices.resize(3, num_vertices);
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j)
      for (int k = 0; k <= nz; ++k) {
        const int v = vertex_of_point[grid.PointIndex(i, j, k)];
        if (v >= 0) mesh.vertices.col(v) = grid.Point(i, j, k);
      }
  mesh.elements.resize(8, num_kept);
  int e = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) {
        if (!keep[grid.CellIndex(i, j, k)]) continue;
        for (int a = 0; a < 8; ++a) {
          mesh.elements(a, e) = vertex_of_point[grid.PointIndex(i + (a >> 2 & 1), j + (a >> 1 & 1), k + (a & 1))];
        }
        ++e;
      }
  return mesh;
}

}  // namespace diffpd::internal
