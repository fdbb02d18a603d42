// Tetrahedral meshes from TetGen: its .node/.ele files and its program.
#pragma once

#include <string>

#include "diffpd/mesh.h"
#include "diffpd/surface_mesh.h"

namespace diffpd {

// Reads a TetGen mesh (tet4) from a .node and a .ele file.
//  .node: header "<#points> 3 <#attributes> <#boundary markers>", then one line
//         "<point #> x y z [attributes] [marker]" per point;
//  .ele:  header "<#tets> 4 <#attributes>", then "<tet #> n0 n1 n2 n3 [attributes]".
// The first point number (0 or 1) sets the base of the node numbering, used by
// the node references in the .ele file; point and tet numbers must then run
// consecutively. Attributes and boundary markers are ignored, '#' starts a
// comment. Tets are taken as written (no reordering), so an inverted tet is
// reported by ValidateMesh, which is called with ele_path as `what` (its
// vertex indices are 0-based even for a 1-based file).
// Throws InvalidInputError "<path>:<line>: <message>", for example
//   "cannot open '<path>'", "cannot open '<path>': it is a directory, not a file",
//   "<node_path>:1: expected dimension 3, got 2",
//   "<node_path>:1: the number of points = 1000000000 is more than the file's 25 bytes can hold"
//   (a count is checked against the file's size before anything is allocated),
//   "<node_path>:2: first point number must be 0 or 1, got 5",
//   "<node_path>:4: point number 7 out of sequence (expected 3)",
//   "<node_path>: file ends after 2 of 5 points",
//   "<ele_path>:1: only 4-node tetrahedra are supported, got 10 nodes per tetrahedron",
//   "<ele_path>:3: node 9 out of range (the .node file numbers its 5 points 1..5)",
// and any ValidateMesh message.
Mesh ReadTetGen(const std::string& node_path, const std::string& ele_path);

// Tetrahedralizes the interior of a closed triangle surface with the TetGen
// program (Debian package 'tetgen', found on PATH) after scaling the vertices
// by `scale` about the origin. `switches` are TetGen's command-line switches
// without the leading '-' (default "pq1.414Y": a PLC, radius-edge ratio
// <= 1.414, boundary facets kept unsplit so the surface is reproduced
// exactly). The surface is written to a .smesh file in a fresh temporary
// directory, `tetgen -<switches>` is run on it with its output captured, the
// resulting .node/.ele are read back and the directory is removed.
// TetGen's tet orientation is not part of its documented format (1.5 writes
// positive volumes under mesh.h's convention), so each tet with negative
// signed volume has its last two nodes swapped (here only, not in
// ReadTetGen); points TetGen leaves unused are dropped; then the mesh is
// validated (`what` = "TetrahedralizeSurface").
// Throws InvalidInputError for a bad scale, an empty surface, a triangle
// index out of range, an open surface (before TetGen runs; message as
// VoxelizeSurface's, "TetrahedralizeSurface: the surface is not closed: ..."),
// or invalid switches (empty, containing whitespace or
// '-', or one of 'r', 'N', 'E', 'I', which change what TetGen reads or
// writes), and std::runtime_error
//   "tetgen program not found: install the Debian package 'tetgen'",
//   "tetgen failed (exit status 1) with switches '...': <its last 5 output lines>"
//   (or "(killed by signal 6)": TetGen 1.5 aborts on a surface it cannot mesh),
// or when TetGen writes no .node/.ele file.
Mesh TetrahedralizeSurface(const SurfaceMesh& surface, const std::string& switches = "pq1.414Y", double scale = 1.0);

}  // namespace diffpd
