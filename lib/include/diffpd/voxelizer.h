// Hexahedral meshes from implicit or triangle-surface shapes by voxelization.
#pragma once

#include <functional>

#include <Eigen/Core>

#include "diffpd/mesh.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/types.h"

namespace diffpd {

// Keeps the cells of the grid {origin + dx [i, i+1] x [j, j+1] x [k, k+1]},
// 0 <= i < cells(0) etc., whose centre c satisfies sdf(c) < 0 (sdf in metres,
// negative inside). Kept cells share their corner nodes; vertices are
// numbered compactly in grid-point order (i (ny+1) + j)(nz+1) + k and
// elements in cell order (i ny + j) nz + k; unused grid points are dropped.
// Example: a sphere of radius 0.05 at the origin, origin = (-0.05,)*3,
// cells = (10, 10, 10), dx = 0.01 gives 552 hexes and 823 vertices.
// Throws InvalidInputError if sdf is empty, a cell count is < 1, dx is not
// finite and > 0, the origin is not finite, the grid has more than 10^8
// cells ("VoxelizeSdf: cells = (1000, 1000, 1000) is 1e+09 cells, more than
// the limit of 1e+08": the mesh alone would take gigabytes), sdf returns NaN,
// or no cell is kept.
Mesh VoxelizeSdf(const std::function<double(const Vec3&)>& sdf, const Vec3& origin, const Eigen::Vector3i& cells,
                 double dx);

// Voxelizes a closed triangle surface (outward or inward oriented) after
// scaling its vertices by `scale` about the origin. The grid of cubes of edge
// dx covers the scaled bounding box [lo, hi] and is centred on it:
// cells(d) = max(1, ceil((hi_d - lo_d) / dx)), origin = (lo + hi - dx cells) / 2.
// A cell is kept if its centre is inside, decided by the parity of crossings
// of axis-parallel rays along x, y and z with a majority vote of the three
// (ties on edges and vertices are broken consistently). Mesh numbering as in
// VoxelizeSdf. The surface must be closed: every edge in an even number of
// triangles (2 on a manifold surface, 4 where it touches itself along an
// edge), else the parity of crossings means nothing. Throws
// InvalidInputError if dx or scale is not finite and > 0, the surface has no
// triangles or an out-of-range index, is open ("VoxelizeSurface: the surface
// is not closed: 3 boundary edges, the first (0, 1) (a closed surface has
// every edge in an even number of triangles)"), the grid would exceed 10^8
// cells (as in VoxelizeSdf, with dx and the box size appended), or no cell
// centre is inside.
Mesh VoxelizeSurface(const SurfaceMesh& surface, double dx, double scale = 1.0);

}  // namespace diffpd
