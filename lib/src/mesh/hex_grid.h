// A regular grid of hexahedral cells and the mesh of a subset of its cells
// (internal; shared by MakeBoxHexMesh and the voxelizers).
#pragma once

#include <string>
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

// The most cells a grid may have (MakeBoxHexMesh, VoxelizeSdf,
// VoxelizeSurface): 10^8. The mesh of a full grid of that size holds 3.2 GB
// of node indices and 2.4 GB of vertices before any simulation data; larger
// requests are refused up front rather than failing in an allocation.
inline constexpr double kMaxGridCells = 1e8;

// Throws InvalidInputError "<function>: cells = (a, b, c) is 1e+12 cells, more
// than the limit of 1e+08" when the product of the (positive) counts exceeds
// kMaxGridCells; `detail` is appended to the message (e.g. the dx that led
// to the counts).
void CheckGridSize(const std::string& function, const Eigen::Vector3d& cells, const std::string& detail = "");

// Hex8 mesh of the cells with keep[CellIndex] true, elements ordered by cell
// index; the grid points they use become vertices, numbered compactly in
// grid-point order (unused points are dropped). keep.size() == num_cells().
Mesh MeshFromCells(const HexGrid& grid, const std::vector<bool>& keep);

}  // namespace diffpd::internal
