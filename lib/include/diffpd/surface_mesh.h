// Closed triangle surfaces: OBJ input, inside/outside queries, checks.
#pragma once

#include <string>

#include <Eigen/Core>

#include "diffpd/types.h"

namespace diffpd {

struct SurfaceMesh {
  // 3 x n vertex positions (units of the source, usually metres).
  Eigen::Matrix3Xd vertices;
  // 3 x t vertex indices in [0, n), one column per triangle. A closed surface
  // is "outward oriented" when every triangle (a, b, c) is counterclockwise
  // seen from outside, i.e. (x_b - x_a) x (x_c - x_a) points out.
  Eigen::Matrix3Xi triangles;
};

// Reads a Wavefront OBJ file: "v x y z [w]" lines (w ignored) and
// "f i j k ..." lines whose entries may be "i", "i/t", "i//n" or "i/t/n"
// (t and n integers, ignored; any other entry is malformed).
// Indices are 1-based; a negative index -r means the r-th vertex before the
// face line (-1 = the last one read so far). A face with p > 3 vertices is
// fan-triangulated into (0,1,2), (0,2,3), ..., (0,p-2,p-1). All other lines
// (vn, vt, o, g, s, usemtl, mtllib, '#' comments) are ignored.
// Throws InvalidInputError, "<path>:<line>: ..." for a malformed line:
//   "cannot open '<path>'", "cannot open '<path>': it is a directory, not a file",
//   "<path>:<line>: expected x y z coordinates, got 'v 1 2'",
//   "<path>:<line>: expected x coordinate (a finite number), got 'abc'",
//   "<path>:<line>: a face needs at least 3 vertices, got 2",
//   "<path>:<line>: malformed face entry '1/a'",
//   "<path>:<line>: face index 0 is invalid (OBJ indices start at 1)",
//   "<path>:<line>: face index 12 out of range (file has 10 vertices)",
//   "<path>:<line>: face index -12 out of range (10 vertices read before this line)",
//   "<path>: no faces" (or "no vertices").
SurfaceMesh ReadObj(const std::string& path);

// Generalized winding number of the surface around point p:
//   w(p) = sum over triangles of Omega_t(p) / (4 pi),
// Omega_t the signed solid angle (Van Oosterom & Strackee):
//   tan(Omega/2) = a.(b x c) / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|),
// a, b, c the corners relative to p. For a closed outward-oriented surface
// w = 1 inside, 0 outside (-1 inside if inward oriented); it degrades
// gracefully on surfaces with small holes. Cost O(#triangles). Undefined
// (may be any value) for p on the surface.
double WindingNumber(const SurfaceMesh& surface, const Vec3& p);

// Volume enclosed by a closed surface by the divergence theorem:
//   V = sum over triangles of x_a . (x_b x x_c) / 6  (units of vertices cubed).
// Positive for outward orientation, negative for inward; meaningless for an
// open surface.
double EnclosedVolume(const SurfaceMesh& surface);

// Throws InvalidInputError unless the surface is a closed, consistently
// oriented triangle surface. Checked in this order, first failure reported:
//   "<what>: the surface has no triangles",
//   "<what>: triangle 4 references vertex 99, but the surface has 50 vertices",
//   "<what>: triangle 4 repeats vertex 2",
//   "<what>: edge (3, 7) is used by 1 triangle(s); a closed surface needs exactly 2",
//   "<what>: edge (3, 7) has the same direction in triangles 5 and 9 (inconsistent orientation)".
// Edges are reported with the smaller vertex index first. Does not check
// self-intersections nor whether the orientation is outward (see EnclosedVolume).
void ValidateWatertight(const SurfaceMesh& surface, const std::string& what = "surface");

}  // namespace diffpd
