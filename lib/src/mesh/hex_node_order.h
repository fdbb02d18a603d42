// Hex8 node order of Gmsh and VTK versus ours (internal).
//
// Gmsh and VTK number the corners of the reference hex [-1,1]^3 as
//   0 (-,-,-) 1 (+,-,-) 2 (+,+,-) 3 (-,+,-) 4 (-,-,+) 5 (+,-,+) 6 (+,+,+) 7 (-,+,+);
// ours (mesh.h) numbers corner (2i-1, 2j-1, 2k-1) as a = 4 i + 2 j + k.
#pragma once

namespace diffpd::internal {

// Our node a is Gmsh/VTK node kGmshHexNodeOfOurs[a]:
//   ours[a] = gmsh[kGmshHexNodeOfOurs[a]],  vtk[kGmshHexNodeOfOurs[a]] = ours[a].
constexpr int kGmshHexNodeOfOurs[8] = {0, 4, 3, 7, 1, 5, 2, 6};
// The inverse permutation: Gmsh/VTK node b is our node kOursHexNodeOfGmsh[b].
constexpr int kOursHexNodeOfGmsh[8] = {0, 4, 6, 2, 1, 5, 7, 3};

}  // namespace diffpd::internal
