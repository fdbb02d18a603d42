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

// Checks a mesh and throws InvalidInputError naming the first violation.
// `what` names the mesh in messages (e.g. a file name). Checks, in order, and
// their messages (indices are 0-based; volumes in m^3, printed with 6
// significant digits):
//  0. a declared type:          "<what>: type = 7 is invalid: must be ElementType::kTet4 (0) or kHex8 (1)"
//  1. at least one element:     "<what>: the mesh has no elements"
//  2. k rows in `elements`:     "<what>: elements must have 8 rows for hex8, got 4"
//  3. finite coordinates:       "<what>: vertex 5 has a non-finite coordinate"
//  4. indices in [0, n):        "<what>: element 3 references vertex 99, but the mesh has 50 vertices"
//  5. distinct element nodes:   "<what>: element 4 repeats vertex 2"
//     (4 and 5 are checked element by element, 6 likewise)
//  6. positive volume:          "<what>: element 12 is inverted or degenerate (signed volume -1.5e-07 m^3)"
//     An element is degenerate when its signed volume V <= 1e-12 V_box, V_box
//     the volume of its axis-aligned bounding box (a scale-free threshold).
//     Hexes must also have det J > 1e-12 V_box / 8 at each of the 8 Gauss
//     points (V = sum of det J there):
//       "<what>: element 12 is inverted or degenerate (signed volume 0.2875 m^3; det J = -0.0965905 at Gauss point 7)"
//  7. every vertex referenced:  "<what>: vertex 7 is not referenced by any element"
void ValidateMesh(const Mesh& mesh, const std::string& what = "mesh");

// Signed volume of element e at the given positions (3 x n): for tets the
// usual determinant formula det[x1-x0, x2-x0, x3-x0] / 6, for hexes the
// integral of det J over the reference cube by 2x2x2 Gauss quadrature (exact
// for the trilinear map). Units of positions cubed. Does not validate.
double SignedElementVolume(const Mesh& mesh, const Eigen::Matrix3Xd& positions, int e);

}  // namespace diffpd
