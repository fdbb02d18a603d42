// A regular grid of hexahedral cells and the mesh of a subset of its cells
// (internal; shared by MakeBoxHexMesh and the voxelizers).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "diffpd/mesh.h"

namespace diffpd::internal {

struct HexGrid {
  Eigen::Vector3d origin;   // corner of cell (0, 0, 0), metres
  Eigen::Vector3i cells;    // number of cells per axis, each >= 1
  Eigen::Vector3d spacing;  // cell edge lengths, metres, each > 0

  long num_cells() const { return static_cast<long>(cells(0)) * cells(1) * cells(2); }
  // Cell (i, j, k) has index (i ny + j) nz + k.
  long CellIndex(int i, int j, int k) const { return (static_cast<long>(i) * cells(1) + j) * cells(2) + k; }
  // Grid point (i, j, k) has index (i (ny+1) + j)(nz+1) + k.
  long PointIndex(int i, int j, int k) const {
    return (static_cast<long>(i) * (cells(1) + 1) + j) * (cells(2) + 1) + k;
  }
  Eigen::Vector3d Point(int i, int j, int k) const { return origin + Eigen::Vector3d(i, j, k).cwiseProduct(spacing); }
  Eigen::Vector3d CellCentre(int i, int j, int k) const {
    return origin + Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5).cwiseProduct(spacing);
  }
};

// Hex8 mesh of the cells with keep[CellIndex] true, elements ordered by cell
// index; the grid points they use become vertices, numbered compactly in
// grid-point order (unused points are dropped). keep.size() == num_cells().
Mesh MeshFromCells(const HexGrid& grid, const std::vector<bool>& keep);

}  // namespace diffpd::internal
