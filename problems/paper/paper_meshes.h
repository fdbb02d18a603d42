// Meshes of the paper's rows and the node and element sets read off them,
// with the conventions of the original code (PROBLEMS.md, "Voxel meshes
// generated in code" and "Contact candidates").
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "diffpd/mesh.h"
#include "diffpd/types.h"

namespace diffpd::problems {

// The grid of cells origin + dx [i, i+1] x [j, j+1] x [k, k+1], 0 <= i <
// cells(0) etc., keeping the cells for which occupied(i, j, k) is true. Nodes
// are the corners of kept cells, numbered lexicographically (i slowest, k
// fastest); elements are the kept cells in the same order; hex corner a =
// 4 di + 2 dj + dk (mesh.h). Throws InvalidInputError as VoxelizeSdf does
// (no cell kept, bad cell counts or dx).
Mesh VoxelCells(const std::function<bool(int, int, int)>& occupied, const Eigen::Vector3i& cells, double dx,
                const Vec3& origin = Vec3::Zero());

// meshes/<file> of the paper's shared data (Gmsh 4.1 hex8, read in place),
// its vertices multiplied by `scale` about the origin. Throws what
// SharedDataPath and ReadGmsh throw.
Mesh ReadPaperMesh(const std::string& file, double scale = 1.0);

// The elements e of `mesh` with keep(e) true, in their order, and the nodes
// they use, in their order (a cropped mesh). Throws InvalidInputError if no
// element is kept.
Mesh KeepElements(const Mesh& mesh, const std::function<bool(int)>& keep);

// Nodes that belong to exactly one element, in increasing order.
std::vector<int> SingleElementNodes(const Mesh& mesh);
// Nodes whose rest position satisfies `keep`, in increasing order.
std::vector<int> NodesWhere(const Mesh& mesh, const std::function<bool(const Vec3&)>& keep);
// The mean of element e's corner positions at rest (m).
Vec3 ElementCentre(const Mesh& mesh, int e);
// The grid cell (i, j, k) of hex element e of a voxel mesh with cell size dx
// whose grid starts at the origin: round(lowest corner / dx) per axis.
Eigen::Vector3i ElementCell(const Mesh& mesh, int e, double dx);

}  // namespace diffpd::problems
