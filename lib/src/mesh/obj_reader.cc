// ReadObj (declared in surface_mesh.h).
#include <string>
#include <vector>

#include "diffpd/error.h"
#include "diffpd/surface_mesh.h"
#include "mesh/line_reader.h"

namespace diffpd {
namespace {

struct FaceCorner {
  long index;  // 0-based once resolved; a positive 1-based index until then
  int line;
};

// The vertex index of a face entry "i", "i/t", "i//n" or "i/t/n" (t and n
// integers, ignored); false for anything else ("1/a", "1/", "1/2/3/4").
bool ParseFaceEntry(const std::string& entry, long* index) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t slash; (slash = entry.find('/', start)) != std::string::npos; start = slash + 1)
    parts.push_back(entry.substr(start, slash - start));
  parts.push_back(entry.substr(start));
  if (parts.size() > 3) return false;
  long ignored = 0;
  for (size_t p = 1; p < parts.size(); ++p) {
    const bool may_be_empty = p == 1 && parts.size() == 3;  // "i//n"
    if (parts[p].empty() ? !may_be_empty : !internal::ParseInt(parts[p], &ignored)) return false;
  }
  return internal::ParseInt(parts[0], index);
}

}  // namespace

SurfaceMesh ReadObj(const std::string& path) {
  internal::LineReader reader(path);
  std::vector<Vec3> vertices;
  std::vector<std::vector<FaceCorner>> faces;  // positive indices resolved at the end
  while (reader.Next()) {
    const std::vector<std::string>& tokens = reader.tokens();
    if (tokens[0] == "v") {
      reader.RequireTokens(4, "x y z coordinates");
      vertices.emplace_back(reader.ParseDouble(1, "x coordinate"), reader.ParseDouble(2, "y coordinate"),
                            reader.ParseDouble(3, "z coordinate"));
    } else if (tokens[0] == "f") {
      if (tokens.size() < 4) {
        reader.Fail("a face needs at least 3 vertices, got " + std::to_string(tokens.size() - 1));
      }
      std::vector<FaceCorner> face;
      for (size_t t = 1; t < tokens.size(); ++t) {
        long index = 0;
        if (!ParseFaceEntry(tokens[t], &index)) {
          reader.Fail("malformed face entry '" + tokens[t] + "'");
        }
        if (index == 0) reader.Fail("face index 0 is invalid (OBJ indices start at 1)");
        if (index < 0) {
          const long count = static_cast<long>(vertices.size());
          if (-index > count) {
            reader.Fail("face index " + std::to_string(index) + " out of range (" + std::to_string(count) +
                        " vertices read before this line)");
          }
          index = count + index + 1;  // to 1-based
        }
        face.push_back({index, reader.line_number()});
      }
      faces.push_back(std::move(face));
    }
  }
  if (vertices.empty()) throw InvalidInputError(path + ": no vertices");
  if (faces.empty()) throw InvalidInputError(path + ": no faces");
  const long n = static_cast<long>(vertices.size());
  SurfaceMesh surface;
  surface.vertices.resize(3, n);
  for (long v = 0; v < n; ++v) surface.vertices.col(v) = vertices[v];
  std::vector<Eigen::Vector3i> triangles;
  for (const std::vector<FaceCorner>& face : faces) {
    for (const FaceCorner& corner : face) {
      if (corner.index > n) {
        throw InvalidInputError(path + ":" + std::to_string(corner.line) + ": face index " +
                                std::to_string(corner.index) + " out of range (file has " + std::to_string(n) +
                                " vertices)");
      }
    }
    for (size_t c = 1; c + 1 < face.size(); ++c) {
      triangles.emplace_back(face[0].index - 1, face[c].index - 1, face[c + 1].index - 1);
    }
  }
  surface.triangles.resize(3, static_cast<long>(triangles.size()));
  for (size_t t = 0; t < triangles.size(); ++t) surface.triangles.col(t) = triangles[t];
  return surface;
}

}  // namespace diffpd
