// Volumetric meshes: linear tetrahedra and trilinear hexahedra.
//
// Node ordering conventions (both checked by ValidateMesh):
//  - Tet4: nodes (0,1,2,3) with positive signed volume
//          det[x1-x0, x2-x0, x3-x0] / 6 > 0.
//  - Hex8: local node a = 4 i + 2 j + k sits at the reference corner
//          (xi, eta, zeta) = (2i-1, 2j-1, 2k-1), i.e. bit 2 is the x
//          direction, bit 1 is y, bit 0 is z. The Jacobian of the trilinear
//          map must be positive at all 8 Gauss points.
#pragma once

#include <string>

#include <Eigen/Core>

namespace diffpd {

enum class ElementType { kTet4, kHex8 };

// Number of nodes of an element type (4 or 8).
int NodesPerElement(ElementType type);
const char* ToString(ElementType type);

struct Mesh {
  ElementType type = ElementType::kHex8;
  // 3 x n rest positions of the nodes, metres.
  Eigen::Matrix3Xd vertices;
  // k x m node indices, k = NodesPerElement(type), one column per element.
  Eigen::MatrixXi elements;

  int num_vertices() const { return static_cast<int>(vertices.cols()); }
  int num_elements() const { return static_cast<int>(elements.cols()); }
  int num_dofs() const { return 3 * num_vertices(); }
};

// Checks a mesh and throws InvalidInputError naming the first violation:
// non-finite coordinates, wrong number of rows in `elements`, an index out of
// [0, n), a repeated node inside an element, a degenerate or inverted element
// (message gives the element index and its signed volume), an unreferenced
// vertex, an empty mesh. `what` names the mesh in messages (e.g. a file name).
void ValidateMesh(const Mesh& mesh, const std::string& what = "mesh");

// Signed volume of element e at the given positions (3 x n): for tets the
// usual determinant formula, for hexes the integral of det J by 2x2x2 Gauss
// quadrature. Does not validate.
double SignedElementVolume(const Mesh& mesh, const Eigen::Matrix3Xd& positions, int e);

}  // namespace diffpd
