// TetrahedralizeSurface (tetgen_io.h): runs the TetGen program.
#include <stdlib.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "diffpd/error.h"
#include "diffpd/tetgen_io.h"
#include "mesh/subprocess.h"
#include "mesh/surface_boundary.h"
#include "mesh/surface_indices.h"
#include "mesh/tetgen_reader.h"

namespace diffpd {
namespace {

namespace fs = std::filesystem;

// A fresh directory under the system temporary directory, removed with its
// contents on destruction.
class TemporaryDirectory {
 public:
  TemporaryDirectory() {
    std::string pattern = (fs::temp_directory_path() / "diffpd-tetgen-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("cannot create a temporary directory like '" + pattern + "'");
    }
    path_ = pattern;
  }
  ~TemporaryDirectory() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TemporaryDirectory(const TemporaryDirectory&) = delete;
  TemporaryDirectory& operator=(const TemporaryDirectory&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

void CheckSwitches(const std::string& switches) {
  if (switches.empty()) throw InvalidInputError("TetrahedralizeSurface: switches are empty");
  for (char c : switches) {
    if (std::isspace(static_cast<unsigned char>(c)) || c == '-') {
      throw InvalidInputError("TetrahedralizeSurface: switches '" + switches +
                              "' must be one word without '-' or spaces, e.g. \"pq1.414Y\"");
    }
    if (c == 'r' || c == 'N' || c == 'E' || c == 'I') {
      throw InvalidInputError("TetrahedralizeSurface: switch '" + std::string(1, c) + "' in '" + switches +
                              "' is not supported (it changes the files TetGen reads or writes)");
    }
  }
}

// Writes the surface as a TetGen .smesh file (1-based, no holes or regions).
void WriteSmesh(const fs::path& path, const SurfaceMesh& surface) {
  std::ofstream out(path);
  out.precision(17);
  out << surface.vertices.cols() << " 3 0 0\n";
  for (int v = 0; v < surface.vertices.cols(); ++v) {
    out << v + 1 << ' ' << surface.vertices(0, v) << ' ' << surface.vertices(1, v) << ' ' << surface.vertices(2, v)
        << '\n';
  }
  out << surface.triangles.cols() << " 0\n";
  for (int t = 0; t < surface.triangles.cols(); ++t) {
    out << "3 " << surface.triangles(0, t) + 1 << ' ' << surface.triangles(1, t) + 1 << ' '
        << surface.triangles(2, t) + 1 << '\n';
  }
  out << "0\n0\n";
  if (!out) throw std::runtime_error("cannot write '" + path.string() + "'");
}

// The last `count` non-empty lines of `text`, or "(no output)".
std::string Tail(const std::string& text, size_t count) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(line);
  std::string tail;
  for (size_t i = lines.size() > count ? lines.size() - count : 0; i < lines.size(); ++i) {
    tail += (tail.empty() ? "" : "\n") + lines[i];
  }
  return tail.empty() ? "(no output)" : tail;
}

// Drops the vertices no element references, renumbering the rest in order.
void RemoveUnreferencedVertices(Mesh* mesh) {
  std::vector<int> new_index(mesh->num_vertices(), -1);
  for (int e = 0; e < mesh->num_elements(); ++e)
    for (int a = 0; a < mesh->elements.rows(); ++a) new_index[mesh->elements(a, e)] = 0;
  int count = 0;
  for (int& index : new_index)
    if (index == 0) index = count++;
  Eigen::Matrix3Xd vertices(3, count);
  for (int v = 0; v < mesh->num_vertices(); ++v)
    if (new_index[v] >= 0) vertices.col(new_index[v]) = mesh->vertices.col(v);
  for (int e = 0; e < mesh->num_elements(); ++e)
    for (int a = 0; a < mesh->elements.rows(); ++a) mesh->elements(a, e) = new_index[mesh->elements(a, e)];
  mesh->vertices = std::move(vertices);
}

}  // namespace

Mesh TetrahedralizeSurface(const SurfaceMesh& surface, const std::string& switches, double scale) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    std::ostringstream s;
    s << "TetrahedralizeSurface: scale = " << scale << ", must be finite and > 0";
    throw InvalidInputError(s.str());
  }
  internal::CheckTriangleIndices(surface, "TetrahedralizeSurface");
  internal::CheckClosed(surface, "TetrahedralizeSurface");
  CheckSwitches(switches);
  const std::string tetgen = internal::FindOnPath("tetgen");
  if (tetgen.empty()) throw std::runtime_error("tetgen program not found: install the Debian package 'tetgen'");

  const TemporaryDirectory directory;
  SurfaceMesh scaled = surface;
  scaled.vertices *= scale;
  const fs::path input = directory.path() / "surface.smesh";
  WriteSmesh(input, scaled);
  const internal::ProgramResult result =
      internal::RunProgram(tetgen, {"-" + switches, input.string()}, (directory.path() / "tetgen.log").string());
  if (result.exit_status != 0) {
    std::ostringstream s;
    s << "tetgen failed (";
    if (result.signal != 0) {
      s << "killed by signal " << result.signal;
    } else {
      s << "exit status " << result.exit_status;
    }
    s << ") with switches '" << switches << "': " << Tail(result.output, 5);
    throw std::runtime_error(s.str());
  }
  const fs::path node = directory.path() / "surface.1.node";
  const fs::path ele = directory.path() / "surface.1.ele";
  if (!fs::exists(node) || !fs::exists(ele)) {
    throw std::runtime_error("tetgen with switches '" + switches +
                             "' wrote no surface.1.node/.ele: " + Tail(result.output, 5));
  }
  Mesh mesh = internal::ReadTetGenFiles(node.string(), ele.string());
  for (int e = 0; e < mesh.num_elements(); ++e) {
    if (SignedElementVolume(mesh, mesh.vertices, e) < 0.0) std::swap(mesh.elements(2, e), mesh.elements(3, e));
  }
  RemoveUnreferencedVertices(&mesh);
  ValidateMesh(mesh, "TetrahedralizeSurface");
  return mesh;
}

}  // namespace diffpd
