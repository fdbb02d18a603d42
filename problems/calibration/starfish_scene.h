// The simulated starfish (after the shared data/starfish/FACTS.md): its
// tetrahedral mesh, the markers M1..M4, the fixed central column, the four arm
// muscles and the water.
//
// The body: the shared starfish_half_simplified.obj (metres) tetrahedralised
// by TetGen with switches "pq2Y" (surface kept, radius-edge ratio <= 2):
// 780 nodes, 2163 linear tets. pd-corotated + pd-volume, density 400 kg/m^3,
// E = 5e5 Pa, nu = 0.4 (the starting guess of a fit), no gravity, no contact.
// Boundary: every node with |y| < 18 mm and |z| < 18 mm has y and z fixed (x
// free). Four muscles (one per arm, k = 2e6 Pa; -z, +z, -y, +y arm): the
// elements with a face on the flat face x = 0 (>= 3 nodes within 1 mm of
// it; the fact sheet's "a node within 1 mm" takes in, on this coarse mesh,
// tets spanning the thin arm tips' whole thickness, which shorten the arms
// instead of curling them), centroid in the arm's central strip (|y| <= 7.5
// mm for z-arms, |z| <= 7.5 mm for y-arms) and beyond the central square;
// fibres along the arm. Water: drag and thrust on every boundary triangle
// (state_forces.h, fluid density 1000 kg/m^3, Cd from 0.05 along the face to
// 2.05 normal to it, no separate thrust term: the normal pressure is the
// normal drag).
#pragma once

#include <array>
#include <string>

#include "diffpd/scene.h"

namespace diffpd::problems {

inline constexpr const char* kStarfishTetgenSwitches = "pq2Y";

// Material regions of the starfish.
enum class StarfishRegions {
  kNone,      // one material
  kBodyArms,  // material region 0: the four arms (element centroid beyond
              // the central square |y|, |z| < 18 mm), with its own material;
              // the central body keeps the base material
};
// "none", "body-arms".
const char* ToString(StarfishRegions regions);
// Throws InvalidInputError for other names:
//   "--regions = 'legs' is invalid: calibrate-starfish knows 'body-arms'".
StarfishRegions ParseStarfishRegions(const std::string& name);

// The mesh of the file comment (tetgen must be on PATH; reads the shared OBJ).
Mesh StarfishMesh();
// Vertices of M1..M4 (FACTS.md's rule) on `mesh`, in metres. Throws
// InvalidInputError if a marker has no candidate vertex.
std::array<int, 4> StarfishMarkerVertices(const Mesh& mesh);
// The scene of the file comment (with kBodyArms the arms' region starts at
// the base material).
Scene MakeStarfishScene(StarfishRegions regions);

}  // namespace diffpd::problems
