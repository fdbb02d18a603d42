// Structured hexahedral meshes of an axis-aligned box.
#pragma once

#include <Eigen/Core>

#include "diffpd/mesh.h"
#include "diffpd/types.h"

namespace diffpd {

// A grid of cells(0) x cells(1) x cells(2) equal hexahedra spanning the box
// [origin, origin + size] (metres).
//  - Grid point (i, j, k), 0 <= i <= nx etc., is vertex (i (ny+1) + j)(nz+1) + k
//    at origin + (i size_x / nx, j size_y / ny, k size_z / nz).
//  - Cell (i, j, k) is element (i ny + j) nz + k; its local node a = 4 di + 2 dj + dk
//    is grid point (i + di, j + dj, k + dk) (mesh.h's hex8 convention).
// Result: (nx+1)(ny+1)(nz+1) vertices, nx ny nz elements, each of volume
// size_x size_y size_z / (nx ny nz).
// Throws InvalidInputError if a cell count is < 1, a size is not finite and
// > 0, the origin is not finite, or the grid has more than 10^8 cells
// ("MakeBoxHexMesh: cells = (2000, 2000, 2000) is 8e+09 cells, more than the
// limit of 1e+08").
Mesh MakeBoxHexMesh(const Eigen::Vector3i& cells, const Vec3& size, const Vec3& origin = Vec3::Zero());

}  // namespace diffpd
