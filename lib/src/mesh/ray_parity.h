// Inside/outside classification of grid cell centres against a closed
// triangle surface by axis-parallel ray parity (internal).
#pragma once

#include <vector>

#include "diffpd/surface_mesh.h"
#include "mesh/hex_grid.h"

namespace diffpd::internal {

// For each cell of `grid` (indexed by HexGrid::CellIndex), whether its centre
// is inside `surface`: for each axis d the rays parallel to d through the
// cell-centre columns are intersected with the triangles, a centre is inside
// along d when an odd number of crossings lies below it, and the three axes
// vote. A column through a triangle edge or vertex is assigned to exactly one
// of the triangles sharing it (a top-left rule on the projection, evaluated
// antisymmetrically so that neighbours agree); triangles parallel to d are
// skipped. The surface indices must be valid.
std::vector<bool> InsideByRayParity(const SurfaceMesh& surface, const HexGrid& grid);

}  // namespace diffpd::internal
