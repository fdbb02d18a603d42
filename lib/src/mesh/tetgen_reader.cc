// ReadTetGen (tetgen_io.h) and its unvalidated core.
#include "mesh/tetgen_reader.h"

#include <string>

#include "diffpd/error.h"
#include "diffpd/types.h"
#include "diffpd/tetgen_io.h"
#include "mesh/line_reader.h"

namespace diffpd {
namespace internal {
namespace {

// Reads the "<count> ..." header line; returns the count.
long ReadCount(LineReader* reader, const char* items) {
  if (!reader->Next()) reader->Fail(std::string("expected a header line with the number of ") + items);
  return reader->ParseCount(0, std::string("the number of ") + items);
}

// Reads the item number of the current line: the first one sets the base (0
// or 1), later ones must be base + item.
void ReadItemNumber(const LineReader& reader, const char* name, long item, long* base) {
  const long number = reader.ParseInt(0, std::string(name) + " number");
  if (item == 0) {
    if (number != 0 && number != 1) {
      reader.Fail(std::string("first ") + name + " number must be 0 or 1, got " + std::to_string(number));
    }
    *base = number;
  } else if (number != *base + item) {
    reader.Fail(std::string(name) + " number " + std::to_string(number) + " out of sequence (expected " +
                std::to_string(*base + item) + ")");
  }
}

[[noreturn]] void FailShort(const LineReader& reader, long read, long count, const char* items) {
  throw InvalidInputError(reader.path() + ": file ends after " + std::to_string(read) + " of " + std::to_string(count) +
                          " " + items);
}

}  // namespace

Mesh ReadTetGenFiles(const std::string& node_path, const std::string& ele_path) {
  Mesh mesh;
  mesh.type = ElementType::kTet4;
  LineReader nodes(node_path);
  const long num_points = ReadCount(&nodes, "points");
  const long dimension = nodes.ParseInt(1, "the dimension");
  if (dimension != 3) nodes.Fail("expected dimension 3, got " + std::to_string(dimension));
  mesh.vertices.resize(3, num_points);
  long node_base = 0;
  for (long p = 0; p < num_points; ++p) {
    if (!nodes.Next()) FailShort(nodes, p, num_points, "points");
    ReadItemNumber(nodes, "point", p, &node_base);
    mesh.vertices.col(p) = Vec3(nodes.ParseDouble(1, "x coordinate"), nodes.ParseDouble(2, "y coordinate"),
                                nodes.ParseDouble(3, "z coordinate"));
  }
  LineReader elements(ele_path);
  const long num_tets = ReadCount(&elements, "tetrahedra");
  const long nodes_per_tet = elements.ParseInt(1, "the number of nodes per tetrahedron");
  if (nodes_per_tet != 4) {
    elements.Fail("only 4-node tetrahedra are supported, got " + std::to_string(nodes_per_tet) +
                  " nodes per tetrahedron");
  }
  mesh.elements.resize(4, num_tets);
  long tet_base = 0;
  for (long t = 0; t < num_tets; ++t) {
    if (!elements.Next()) FailShort(elements, t, num_tets, "tetrahedra");
    ReadItemNumber(elements, "tetrahedron", t, &tet_base);
    for (int a = 0; a < 4; ++a) {
      const long node = elements.ParseInt(1 + a, "node number");
      if (node < node_base || node >= node_base + num_points) {
        elements.Fail("node " + std::to_string(node) + " out of range (the .node file numbers its " +
                      std::to_string(num_points) + " points " + std::to_string(node_base) + ".." +
                      std::to_string(node_base + num_points - 1) + ")");
      }
      mesh.elements(a, t) = static_cast<int>(node - node_base);
    }
  }
  return mesh;
}

}  // namespace internal

Mesh ReadTetGen(const std::string& node_path, const std::string& ele_path) {
  Mesh mesh = internal::ReadTetGenFiles(node_path, ele_path);
  ValidateMesh(mesh, ele_path);
  return mesh;
}

}  // namespace diffpd
