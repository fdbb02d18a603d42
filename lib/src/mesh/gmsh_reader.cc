// ReadGmsh (gmsh_io.h).
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "diffpd/error.h"
#include "diffpd/types.h"
#include "diffpd/gmsh_io.h"
#include "mesh/hex_node_order.h"
#include "mesh/line_reader.h"

namespace diffpd {
namespace {

struct GmshData {
  std::unordered_map<long, int> node_of_tag;  // tag -> index in positions
  std::vector<Vec3> positions;                // in $Nodes order
  std::optional<ElementType> type;
  std::vector<std::vector<int>> elements;  // node indices into positions, our order
};

void ExpectEnd(internal::LineReader* reader, const std::string& section) {
  if (!reader->Next()) reader->Fail("section $" + section + " has no $End" + section);
  if (reader->line() != "$End" + section) reader->Fail("expected $End" + section + ", got '" + reader->line() + "'");
}

void NextLine(internal::LineReader* reader, const std::string& section) {
  if (!reader->Next()) reader->Fail("section $" + section + " has no $End" + section);
}

void ReadFormat(internal::LineReader* reader) {
  NextLine(reader, "MeshFormat");
  const std::string version = reader->tokens()[0];
  if (version != "4.1") {
    reader->Fail("MSH version " + version + " is not supported; only 4.1 (export with 'gmsh -format msh41')");
  }
  if (reader->ParseInt(1, "file type") != 0) {
    reader->Fail("binary MSH files are not supported; export ASCII (Gmsh option Mesh.Binary = 0)");
  }
  ExpectEnd(reader, "MeshFormat");
}

void ReadNodes(internal::LineReader* reader, GmshData* data) {
  NextLine(reader, "Nodes");
  const long num_blocks = reader->ParseCount(0, "numEntityBlocks");
  for (long b = 0; b < num_blocks; ++b) {
    NextLine(reader, "Nodes");
    const long count = reader->ParseCount(3, "numNodesInBlock");
    const size_t first = data->positions.size();
    for (long n = 0; n < count; ++n) {
      NextLine(reader, "Nodes");
      const long tag = reader->ParseInt(0, "node tag");
      if (tag < 1) reader->Fail("node tag " + std::to_string(tag) + " is invalid: must be >= 1");
      if (!data->node_of_tag.emplace(tag, static_cast<int>(first + n)).second) {
        reader->Fail("node tag " + std::to_string(tag) + " appears twice");
      }
    }
    for (long n = 0; n < count; ++n) {
      NextLine(reader, "Nodes");
      data->positions.emplace_back(reader->ParseDouble(0, "x coordinate"), reader->ParseDouble(1, "y coordinate"),
                                   reader->ParseDouble(2, "z coordinate"));
    }
  }
  ExpectEnd(reader, "Nodes");
}

void ReadElements(internal::LineReader* reader, GmshData* data) {
  NextLine(reader, "Elements");
  const long num_blocks = reader->ParseCount(0, "numEntityBlocks");
  for (long b = 0; b < num_blocks; ++b) {
    NextLine(reader, "Elements");
    const long dimension = reader->ParseInt(0, "entityDim");
    const long gmsh_type = reader->ParseInt(2, "elementType");
    const long count = reader->ParseCount(3, "numElementsInBlock");
    const bool keep = gmsh_type == 4 || gmsh_type == 5;
    if (dimension == 3 && !keep) {
      reader->Fail("3D element type " + std::to_string(gmsh_type) + " is not supported (only 4 = tet4 and 5 = hex8)");
    }
    const ElementType type = gmsh_type == 4 ? ElementType::kTet4 : ElementType::kHex8;
    const int k = NodesPerElement(type);
    for (long e = 0; e < count; ++e) {
      NextLine(reader, "Elements");
      if (!keep) continue;
      if (data->type && *data->type != type) {
        reader->Fail("the file mixes tet4 and hex8 elements (a mesh has one element type)");
      }
      data->type = type;
      const std::string tag = reader->tokens()[0];
      if (reader->tokens().size() != static_cast<size_t>(k) + 1) {
        reader->Fail("element " + tag + " has " + std::to_string(reader->tokens().size() - 1) +
                     " node tags, expected " + std::to_string(k) + " for type " + std::to_string(gmsh_type) + " (" +
                     ToString(type) + ")");
      }
      std::vector<int> nodes(k);
      for (int a = 0; a < k; ++a) {
        const long node_tag = reader->ParseInt(1 + a, "node tag");
        const auto found = data->node_of_tag.find(node_tag);
        if (found == data->node_of_tag.end()) {
          reader->Fail("element " + tag + " references node tag " + std::to_string(node_tag) +
                       ", which is not in $Nodes");
        }
        nodes[a] = found->second;
      }
      if (type == ElementType::kHex8) {
        std::vector<int> ours(8);
        for (int a = 0; a < 8; ++a) ours[a] = nodes[internal::kGmshHexNodeOfOurs[a]];
        nodes = ours;
      }
      data->elements.push_back(nodes);
    }
  }
  ExpectEnd(reader, "Elements");
}

// Skips lines up to and including "$End<section>".
void SkipSection(internal::LineReader* reader, const std::string& section) {
  do {
    NextLine(reader, section);
  } while (reader->line() != "$End" + section);
}

}  // namespace

Mesh ReadGmsh(const std::string& path) {
  internal::LineReader reader(path, '\0');
  if (!reader.Next() || reader.line() != "$MeshFormat") {
    reader.Fail("not a Gmsh MSH file (expected $MeshFormat, got '" + reader.line() + "')");
  }
  ReadFormat(&reader);
  GmshData data;
  while (reader.Next()) {
    const std::string& header = reader.line();
    if (header.empty() || header[0] != '$') reader.Fail("expected a section header ($Name), got '" + header + "'");
    const std::string section = header.substr(1);
    if (section == "Nodes") {
      ReadNodes(&reader, &data);
    } else if (section == "Elements") {
      ReadElements(&reader, &data);
    } else {
      SkipSection(&reader, section);
    }
  }
  if (!data.type) throw InvalidInputError(path + ": no tet4 (type 4) or hex8 (type 5) elements");
  Mesh mesh;
  mesh.type = *data.type;
  const int k = NodesPerElement(mesh.type);
  std::vector<int> vertex_of_node(data.positions.size(), -1);
  for (const std::vector<int>& nodes : data.elements)
    for (int node : nodes) vertex_of_node[node] = 0;
  int num_vertices = 0;
  for (int& v : vertex_of_node)
    if (v == 0) v = num_vertices++;
  mesh.vertices.resize(3, num_vertices);
  for (size_t node = 0; node < data.positions.size(); ++node)
    if (vertex_of_node[node] >= 0) mesh.vertices.col(vertex_of_node[node]) = data.positions[node];
  mesh.elements.resize(k, static_cast<long>(data.elements.size()));
  for (size_t e = 0; e < data.elements.size(); ++e)
    for (int a = 0; a < k; ++a) mesh.elements(a, e) = vertex_of_node[data.elements[e][a]];
  ValidateMesh(mesh, path);
  return mesh;
}

}  // namespace diffpd
