#include "paper/paper_meshes.h"

#include <cmath>
#include <limits>

#include "diffpd/error.h"
#include "diffpd/gmsh_io.h"
#include "diffpd/voxelizer.h"
#include "shared_data.h"

namespace diffpd::problems {

Mesh VoxelCells(const std::function<bool(int, int, int)>& occupied, const Eigen::Vector3i& cells, double dx,
                const Vec3& origin) {
  // VoxelizeSdf keeps a cell when the function is negative at its centre and
  // numbers nodes and cells in the order described above.
  return VoxelizeSdf(
      [&](const Vec3& centre) {
        const Vec3 index = (centre - origin) / dx;
        const int i = static_cast<int>(std::floor(index(0))), j = static_cast<int>(std::floor(index(1))),
                  k = static_cast<int>(std::floor(index(2)));
        return occupied(i, j, k) ? -1.0 : 1.0;
      },
      origin, cells, dx);
}

Mesh ReadPaperMesh(const std::string& file, double scale) {
  Mesh mesh = ReadGmsh(SharedDataPath("paper/meshes/" + file));
  mesh.vertices *= scale;
  return mesh;
}

Mesh KeepElements(const Mesh& mesh, const std::function<bool(int)>& keep) {
  std::vector<int> kept;
  std::vector<int> new_index(mesh.num_vertices(), -1);
  for (int e = 0; e < mesh.num_elements(); ++e)
    if (keep(e)) {
      kept.push_back(e);
      for (int a = 0; a < mesh.elements.rows(); ++a) new_index[mesh.elements(a, e)] = 0;
    }
  if (kept.empty()) throw InvalidInputError("KeepElements: no element is kept");
  int count = 0;
  for (int& i : new_index)
    if (i == 0) i = count++;
  Mesh out;
  out.type = mesh.type;
  out.vertices.resize(3, count);
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (new_index[i] >= 0) out.vertices.col(new_index[i]) = mesh.vertices.col(i);
  out.elements.resize(mesh.elements.rows(), static_cast<int>(kept.size()));
  for (size_t e = 0; e < kept.size(); ++e)
    for (int a = 0; a < mesh.elements.rows(); ++a)
      out.elements(a, static_cast<int>(e)) = new_index[mesh.elements(a, kept[e])];
  return out;
}

std::vector<int> SingleElementNodes(const Mesh& mesh) {
  std::vector<int> count(mesh.num_vertices(), 0);
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < mesh.elements.rows(); ++a) ++count[mesh.elements(a, e)];
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (count[i] == 1) nodes.push_back(i);
  return nodes;
}

std::vector<int> NodesWhere(const Mesh& mesh, const std::function<bool(const Vec3&)>& keep) {
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (keep(mesh.vertices.col(i))) nodes.push_back(i);
  return nodes;
}

Vec3 ElementCentre(const Mesh& mesh, int e) {
  Vec3 c = Vec3::Zero();
  for (int a = 0; a < mesh.elements.rows(); ++a) c += mesh.vertices.col(mesh.elements(a, e));
  return c / static_cast<double>(mesh.elements.rows());
}

Eigen::Vector3i ElementCell(const Mesh& mesh, int e, double dx) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  for (int a = 0; a < mesh.elements.rows(); ++a) lo = lo.cwiseMin(Vec3(mesh.vertices.col(mesh.elements(a, e))));
  return Eigen::Vector3i(std::lround(lo(0) / dx), std::lround(lo(1) / dx), std::lround(lo(2) / dx));
}

}  // namespace diffpd::problems
