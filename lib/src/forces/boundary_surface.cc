// Boundary faces of tetrahedral and hexahedral meshes (see state_forces.h and
// quad_hydrodynamics.h).
#include <algorithm>
#include <array>
#include <map>
#include <vector>

#include <Eigen/Geometry>

#include "diffpd/error.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/state_forces.h"

namespace diffpd {
namespace {

// Faces of an element as cycles of local node indices.
std::vector<std::vector<int>> LocalFaces(ElementType type) {
  if (type == ElementType::kTet4) return {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  // Hex8: local node a = 4 i + 2 j + k; a face fixes one bit, the cycle runs
  // through the other two as (0,0), (0,1), (1,1), (1,0).
  std::vector<std::vector<int>> faces;
  for (int bit = 0; bit < 3; ++bit)
    for (int value = 0; value < 2; ++value) {
      const int b1 = (bit + 1) % 3, b2 = (bit + 2) % 3;
      std::vector<int> cycle;
      for (const auto& [p, q] : {std::pair{0, 0}, std::pair{0, 1}, std::pair{1, 1}, std::pair{1, 0}})
        cycle.push_back((value << (2 - bit)) | (p << (2 - b1)) | (q << (2 - b2)));
      faces.push_back(cycle);
    }
  return faces;
}

struct BoundaryFace {
  std::vector<int> nodes;  // cycle, outward
  int count = 0;
};

std::vector<BoundaryFace> Faces(const Mesh& mesh) {
  const int k = NodesPerElement(mesh.type);
  const auto local = LocalFaces(mesh.type);
  std::map<std::array<int, 4>, BoundaryFace> faces;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    Vec3 centroid = Vec3::Zero();
    for (int a = 0; a < k; ++a) centroid += mesh.vertices.col(mesh.elements(a, e));
    centroid /= k;
    for (const auto& lf : local) {
      std::vector<int> cycle;
      for (const int a : lf) cycle.push_back(mesh.elements(a, e));
      // Orient outward: the (Newell) normal must point away from the centroid.
      Vec3 normal = Vec3::Zero(), center = Vec3::Zero();
      for (size_t t = 0; t < cycle.size(); ++t) {
        const Vec3 p = mesh.vertices.col(cycle[t]), q = mesh.vertices.col(cycle[(t + 1) % cycle.size()]);
        normal += p.cross(q);
        center += p;
      }
      center /= static_cast<double>(cycle.size());
      if (normal.dot(center - centroid) < 0) std::reverse(cycle.begin(), cycle.end());
      std::array<int, 4> key = {-1, -1, -1, -1};
      std::copy(cycle.begin(), cycle.end(), key.begin());
      std::sort(key.begin(), key.end());
      BoundaryFace& f = faces[key];
      if (f.count++ == 0) f.nodes = cycle;
    }
  }
  std::vector<BoundaryFace> out;
  for (auto& [key, f] : faces)
    if (f.count == 1) out.push_back(f);
  return out;
}

}  // namespace

Eigen::Matrix3Xi BoundaryTriangles(const Mesh& mesh) {
  std::vector<std::array<int, 3>> tris;
  for (const BoundaryFace& f : Faces(mesh))
    for (size_t t = 1; t + 1 < f.nodes.size(); ++t) tris.push_back({f.nodes[0], f.nodes[t], f.nodes[t + 1]});
  Eigen::Matrix3Xi out(3, static_cast<Eigen::Index>(tris.size()));
  for (size_t t = 0; t < tris.size(); ++t)
    for (int c = 0; c < 3; ++c) out(c, static_cast<Eigen::Index>(t)) = tris[t][c];
  return out;
}

Eigen::Matrix4Xi BoundaryQuads(const Mesh& mesh) {
  if (mesh.type != ElementType::kHex8)
    throw InvalidInputError(std::string("BoundaryQuads: the mesh has ") + ToString(mesh.type) +
                            " elements; quads need hex8");
  const std::vector<BoundaryFace> faces = Faces(mesh);
  Eigen::Matrix4Xi out(4, static_cast<Eigen::Index>(faces.size()));
  for (size_t f = 0; f < faces.size(); ++f)
    for (int c = 0; c < 4; ++c) out(c, static_cast<Eigen::Index>(f)) = faces[f].nodes[c];
  return out;
}

std::vector<int> BoundaryNodes(const Mesh& mesh) {
  std::vector<int> nodes;
  for (const BoundaryFace& f : Faces(mesh)) nodes.insert(nodes.end(), f.nodes.begin(), f.nodes.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

}  // namespace diffpd
