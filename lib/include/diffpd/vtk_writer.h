// Output of meshes and per-vertex fields for ParaView: VTK XML unstructured
// grids (.vtu) and time series collections (.pvd). ASCII, doubles written
// with 17 significant digits (exact round trip).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "diffpd/mesh.h"

namespace diffpd {

// Named per-vertex fields: each matrix is c x n, c = 1 (scalar) or 3 (vector)
// components, one column per mesh vertex.
using VtkPointData = std::vector<std::pair<std::string, Eigen::MatrixXd>>;

// Writes `mesh` with its vertices at `positions` (3 x n, metres) as a VTK XML
// UnstructuredGrid file: cells are VTK_TETRA (10; same node order as ours) or
// VTK_HEXAHEDRON (12; nodes reordered from mesh.h's convention to VTK's),
// point_data become Float64 PointData arrays. Overwrites `path`.
// Throws InvalidInputError if positions is not 3 x n, a point-data array
// does not have 1 or 3 rows and n columns, a name is empty or repeated or
// contains one of  " & < > ' , or the file cannot be written
// ("cannot write '<path>'").
void WriteVtu(const std::string& path, const Mesh& mesh, const Eigen::Matrix3Xd& positions,
              const VtkPointData& point_data = {});

// A time series for ParaView: one .vtu per frame plus a .pvd index.
//   PvdWriter writer("out/run", "bunny");
//   writer.AddFrame(0.0, mesh, x0);  // writes out/run/bunny_0000.vtu
//   writer.AddFrame(0.01, mesh, x1); // writes out/run/bunny_0001.vtu
//   writer.Write();                  // writes out/run/bunny.pvd
class PvdWriter {
 public:
  // Creates `directory` (and its parents) if missing. `basename` must be a
  // non-empty file name without '/'. Throws InvalidInputError naming the
  // directory if it cannot be created, or naming a bad basename.
  PvdWriter(std::string directory, std::string basename);

  // Writes frame f (f = number of frames added so far) to
  // <directory>/<basename>_<f as 4 or more digits, zero-padded>.vtu with
  // WriteVtu and records it at `time` (seconds; finite, strictly greater
  // than the previous frame's). Throws what WriteVtu throws, and
  // InvalidInputError for a bad time.
  void AddFrame(double time, const Mesh& mesh, const Eigen::Matrix3Xd& positions, const VtkPointData& point_data = {});

  // Writes <directory>/<basename>.pvd listing every frame added so far (file
  // names relative to the .pvd). May be called repeatedly, e.g. after each
  // frame. Throws InvalidInputError "cannot write '<path>'".
  void Write() const;

  int num_frames() const { return static_cast<int>(frames_.size()); }

 private:
  std::string directory_;
  std::string basename_;
  std::vector<std::pair<double, std::string>> frames_;  // (time, .vtu file name)
};

}  // namespace diffpd
