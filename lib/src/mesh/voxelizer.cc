#include "diffpd/voxelizer.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "diffpd/error.h"
#include "mesh/hex_grid.h"
#include "mesh/ray_parity.h"
#include "mesh/surface_boundary.h"
#include "mesh/surface_indices.h"

namespace diffpd {
namespace {

void CheckSpacing(const char* function, const char* name, double value) {
  if (!(value > 0.0) || !std::isfinite(value)) {
    std::ostringstream s;
    s << function << ": " << name << " = " << value << ", must be finite and > 0";
    throw InvalidInputError(s.str());
  }
}

}  // namespace

Mesh VoxelizeSdf(const std::function<double(const Vec3&)>& sdf, const Vec3& origin, const Eigen::Vector3i& cells,
                 double dx) {
  if (!sdf) throw InvalidInputError("VoxelizeSdf: sdf is empty");
  CheckSpacing("VoxelizeSdf", "dx", dx);
  for (int d = 0; d < 3; ++d) {
    std::ostringstream s;
    if (cells(d) < 1) {
      s << "VoxelizeSdf: cells(" << d << ") = " << cells(d) << ", must be >= 1";
      throw InvalidInputError(s.str());
    }
    if (!std::isfinite(origin(d))) {
      s << "VoxelizeSdf: origin(" << d << ") = " << origin(d) << ", must be finite";
      throw InvalidInputError(s.str());
    }
  }
  internal::CheckGridSize("VoxelizeSdf", cells.cast<double>());
  const internal::HexGrid grid{origin, cells, Vec3::Constant(dx)};
  std::vector<bool> keep(grid.num_cells(), false);
  bool any = false;
  for (int i = 0; i < cells(0); ++i)
    for (int j = 0; j < cells(1); ++j)
      for (int k = 0; k < cells(2); ++k) {
        const Vec3 centre = grid.CellCentre(i, j, k);
        const double value = sdf(centre);
        if (std::isnan(value)) {
          std::ostringstream s;
          s << "VoxelizeSdf: sdf returned NaN at cell centre (" << centre.transpose() << ")";
          throw InvalidInputError(s.str());
        }
        keep[grid.CellIndex(i, j, k)] = value < 0.0;
        any = any || value < 0.0;
      }
  if (!any) throw InvalidInputError("VoxelizeSdf: no cell centre has sdf < 0");
  return internal::MeshFromCells(grid, keep);
}

Mesh VoxelizeSurface(const SurfaceMesh& surface, double dx, double scale) {
  CheckSpacing("VoxelizeSurface", "dx", dx);
  CheckSpacing("VoxelizeSurface", "scale", scale);
  internal::CheckTriangleIndices(surface, "VoxelizeSurface");
  internal::CheckClosed(surface, "VoxelizeSurface");
  SurfaceMesh scaled = surface;
  scaled.vertices *= scale;
  if (!scaled.vertices.allFinite()) throw InvalidInputError("VoxelizeSurface: non-finite vertex coordinate");
  const Vec3 lo = scaled.vertices.rowwise().minCoeff();
  const Vec3 hi = scaled.vertices.rowwise().maxCoeff();
  Vec3 counts;
  for (int d = 0; d < 3; ++d) counts(d) = std::max(1.0, std::ceil((hi(d) - lo(d)) / dx));
  std::ostringstream detail;
  detail << " (dx = " << dx << " for a bounding box of size (" << (hi - lo).transpose() << "))";
  internal::CheckGridSize("VoxelizeSurface", counts, detail.str());
  const Eigen::Vector3i cells = counts.cast<int>();
  const internal::HexGrid grid{(lo + hi - dx * cells.cast<double>()) / 2.0, cells, Vec3::Constant(dx)};
  const std::vector<bool> keep = internal::InsideByRayParity(scaled, grid);
  bool any = false;
  for (bool inside : keep) any = any || inside;
  if (!any) {
    std::ostringstream s;
    s << "VoxelizeSurface: no cell centre lies inside the surface (dx = " << dx << ", grid " << cells(0) << " x "
      << cells(1) << " x " << cells(2) << " cells); use a smaller dx or check that the surface is closed";
    throw InvalidInputError(s.str());
  }
  return internal::MeshFromCells(grid, keep);
}

}  // namespace diffpd
