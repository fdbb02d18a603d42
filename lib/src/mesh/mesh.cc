// Element conventions, signed volumes and the mesh validator (see mesh.h).
#include "diffpd/mesh.h"

#include <cmath>
#include <sstream>
#include <vector>

#include <Eigen/Dense>

#include "diffpd/error.h"
#include "diffpd/types.h"
#include "mesh/hex_gauss.h"

namespace diffpd {
namespace {

// Relative threshold of the degeneracy test: an element is degenerate when
// |signed volume| <= kDegenerateRatio * (volume of its axis-aligned bounding box).
constexpr double kDegenerateRatio = 1e-12;

double TetSignedVolume(const Eigen::Matrix3Xd& x, const Eigen::MatrixXi& elements, int e) {
  const Vec3 x0 = x.col(elements(0, e));
  Mat3 edges;
  edges << x.col(elements(1, e)) - x0, x.col(elements(2, e)) - x0, x.col(elements(3, e)) - x0;
  return edges.determinant() / 6.0;
}

double BoundingBoxVolume(const Eigen::Matrix3Xd& x, const Eigen::MatrixXi& elements, int e) {
  Vec3 lo = x.col(elements(0, e));
  Vec3 hi = lo;
  for (int a = 1; a < elements.rows(); ++a) {
    lo = lo.cwiseMin(x.col(elements(a, e)));
    hi = hi.cwiseMax(x.col(elements(a, e)));
  }
  return (hi - lo).prod();
}

[[noreturn]] void Fail(const std::string& what, const std::string& message) {
  throw InvalidInputError(what + ": " + message);
}

}  // namespace

int NodesPerElement(ElementType type) {
  switch (type) {
    case ElementType::kTet4:
      return 4;
    case ElementType::kHex8:
      return 8;
  }
  DIFFPD_CHECK(false, "unknown ElementType " << static_cast<int>(type));
}

const char* ToString(ElementType type) {
  switch (type) {
    case ElementType::kTet4:
      return "tet4";
    case ElementType::kHex8:
      return "hex8";
  }
  return "unknown";
}

double SignedElementVolume(const Mesh& mesh, const Eigen::Matrix3Xd& positions, int e) {
  if (mesh.type == ElementType::kTet4) return TetSignedVolume(positions, mesh.elements, e);
  double volume = 0.0;
  for (int g = 0; g < 8; ++g) volume += internal::HexJacobian(positions, mesh.elements, e, g).determinant();
  return volume;  // every Gauss weight is 1
}

void ValidateMesh(const Mesh& mesh, const std::string& what) {
  if (mesh.type != ElementType::kTet4 && mesh.type != ElementType::kHex8) {
    std::ostringstream s;
    s << "type = " << static_cast<int>(mesh.type) << " is invalid: must be ElementType::kTet4 (0) or kHex8 (1)";
    Fail(what, s.str());
  }
  const int k = NodesPerElement(mesh.type);
  const int n = mesh.num_vertices();
  const int m = mesh.num_elements();
  if (m == 0) Fail(what, "the mesh has no elements");
  if (mesh.elements.rows() != k) {
    std::ostringstream s;
    s << "elements must have " << k << " rows for " << ToString(mesh.type) << ", got " << mesh.elements.rows();
    Fail(what, s.str());
  }
  for (int v = 0; v < n; ++v) {
    if (!mesh.vertices.col(v).allFinite()) {
      Fail(what, "vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  std::vector<bool> referenced(n, false);
  for (int e = 0; e < m; ++e) {
    for (int a = 0; a < k; ++a) {
      const int v = mesh.elements(a, e);
      if (v < 0 || v >= n) {
        std::ostringstream s;
        s << "element " << e << " references vertex " << v << ", but the mesh has " << n << " vertices";
        Fail(what, s.str());
      }
      for (int b = 0; b < a; ++b) {
        if (mesh.elements(b, e) == v) {
          Fail(what, "element " + std::to_string(e) + " repeats vertex " + std::to_string(v));
        }
      }
      referenced[v] = true;
    }
  }
  for (int e = 0; e < m; ++e) {
    const double volume = SignedElementVolume(mesh, mesh.vertices, e);
    const double threshold = kDegenerateRatio * BoundingBoxVolume(mesh.vertices, mesh.elements, e);
    std::ostringstream s;
    s << "element " << e << " is inverted or degenerate (signed volume " << volume << " m^3";
    if (!(volume > threshold)) Fail(what, s.str() + ")");
    if (mesh.type != ElementType::kHex8) continue;
    for (int g = 0; g < 8; ++g) {
      const double det_j = internal::HexJacobian(mesh.vertices, mesh.elements, e, g).determinant();
      if (!(det_j > threshold / 8.0)) {
        s << "; det J = " << det_j << " at Gauss point " << g << ")";
        Fail(what, s.str());
      }
    }
  }
  for (int v = 0; v < n; ++v) {
    if (!referenced[v]) Fail(what, "vertex " + std::to_string(v) + " is not referenced by any element");
  }
}

}  // namespace diffpd
