// Volumetric meshes from Gmsh .msh files.
#pragma once

#include <string>

#include "diffpd/mesh.h"

namespace diffpd {

// Reads a Gmsh MSH 4.1 ASCII file ("$MeshFormat 4.1 0 8"). Uses $Nodes (entity
// blocks; node tags may be any distinct positive integers, in any order) and
// $Elements, keeping elements of type 4 (tet4, node order unchanged) and
// type 5 (hex8, reordered from Gmsh's corner numbering to mesh.h's); lower-
// dimensional elements (points, lines, triangles, quads) are ignored, as are
// all other sections. Vertices are the nodes the kept elements use, in the
// order they appear in $Nodes; elements keep their order in the file.
// The mesh is validated with ValidateMesh(mesh, path).
// Throws InvalidInputError "<path>:<line>: <message>", for example
//   "cannot open '<path>'", "cannot open '<path>': it is a directory, not a file",
//   "<path>:6: numNodesInBlock = 3000000000 is more than the file's 95 bytes can hold"
//   (every count is checked against the file's size before it is used),
//   "<path>:1: not a Gmsh MSH file (expected $MeshFormat, got 'foo')",
//   "<path>:2: MSH version 2.2 is not supported; only 4.1 (export with 'gmsh -format msh41')",
//   "<path>:2: binary MSH files are not supported; export ASCII (Gmsh option Mesh.Binary = 0)",
//   "<path>:9: node tag 3 appears twice", "<path>:9: node tag -3 is invalid: must be >= 1",
//   "<path>:20: element 7 references node tag 99, which is not in $Nodes",
//   "<path>:20: element 7 has 4 node tags, expected 8 for type 5 (hex8)",
//   "<path>:19: 3D element type 11 is not supported (only 4 = tet4 and 5 = hex8)",
//   "<path>:21: the file mixes tet4 and hex8 elements (a mesh has one element type)",
//   "<path>:30: section $Nodes has no $EndNodes",
//   "<path>: no tet4 (type 4) or hex8 (type 5) elements",
// and any ValidateMesh message.
Mesh ReadGmsh(const std::string& path);

}  // namespace diffpd
