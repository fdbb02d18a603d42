#include "diffpd/gmsh_io.h"

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "diffpd/types.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd {
namespace {

const char kHeader[] = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";

// The unit cube as one hex. Node tags are not contiguous and not in order:
// tag 10 g is Gmsh corner g - 1 of the unit cube, listed 50..80 then 10..40;
// tag 90 is a geometry point used only by a point element. A quad (type 3)
// and a point (type 15) are to be ignored.
const char kCube[] =
    "$PhysicalNames\n1\n3 1 \"body with spaces\"\n$EndPhysicalNames\n"
    "$Entities\n1 0 0 1\n1 0 0 0 0\n1 0 0 0 1 1 1 0 0\n$EndEntities\n"
    "$Nodes\n"
    "2 9 10 90\n"
    "0 1 0 1\n90\n0.5 0.5 0.5\n"
    "3 1 0 8\n50\n60\n70\n80\n10\n20\n30\n40\n"
    "0 0 1\n1 0 1\n1 1 1\n0 1 1\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
    "$EndNodes\n"
    "$Elements\n"
    "3 3 1 4\n"
    "0 1 15 1\n4 90\n"
    "2 1 3 1\n3 10 20 30 40\n"
    "3 1 5 1\n1 10 20 30 40 50 60 70 80\n"
    "$EndElements\n";

// Two tets (1,2,3,4) and (2,7,3,4); node 7 lies in a parametric block.
const char kTets[] =
    "$Comments\nanything $Nodes\n$EndComments\n"
    "$Nodes\n"
    "2 5 1 7\n"
    "3 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "2 1 1 1\n7\n1 1 1 0.25 0.75\n"
    "$EndNodes\n"
    "$Elements\n1 2 1 2\n3 1 4 2\n1 1 2 3 4\n2 2 7 3 4\n$EndElements\n";

class ReadGmshTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& text) { return directory_.WriteFile(name, text); }

  // The message of ReadGmsh on `text`, its path replaced by "F".
  std::string ErrorOf(const std::string& text) {
    const std::string path = Write("bad.msh", text);
    std::string message = testing::MessageOf<InvalidInputError>([&] { ReadGmsh(path); });
    if (message.rfind(path, 0) == 0) message = "F" + message.substr(path.size());
    return message;
  }

  const testing::TemporaryDirectory directory_{"diffpd-gmsh-io"};
};

TEST_F(ReadGmshTest, HexWithNonContiguousTags) {
  const Mesh mesh = ReadGmsh(Write("cube.msh", std::string(kHeader) + kCube));
  EXPECT_EQ(mesh.type, ElementType::kHex8);
  ASSERT_EQ(mesh.num_vertices(), 8);  // the point node 90 is dropped
  ASSERT_EQ(mesh.num_elements(), 1);
  EXPECT_EQ(mesh.vertices.col(0), Vec3(0, 0, 1));  // tag 50 comes first in $Nodes
  for (int a = 0; a < 8; ++a) {
    EXPECT_EQ(mesh.vertices.col(mesh.elements(a, 0)), Vec3(a >> 2 & 1, a >> 1 & 1, a & 1)) << a;
  }
  EXPECT_DOUBLE_EQ(SignedElementVolume(mesh, mesh.vertices, 0), 1.0);
}

TEST_F(ReadGmshTest, Tets) {
  const Mesh mesh = ReadGmsh(Write("tets.msh", std::string(kHeader) + kTets));
  EXPECT_EQ(mesh.type, ElementType::kTet4);
  ASSERT_EQ(mesh.num_vertices(), 5);
  EXPECT_EQ(mesh.elements.col(1), Eigen::Vector4i(1, 4, 2, 3));
  EXPECT_EQ(mesh.vertices.col(4), Vec3(1, 1, 1));
}

// Five nodes (tags 1..5) of a unit tetrahedron and the point (1, 1, 1); the
// $Elements section starts on line 19.
const std::string kFiveNodes = std::string(kHeader) +
                               "$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n"
                               "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n$EndNodes\n";

// A malformed .msh text and the exact message, the path replaced by "F".
struct BadMsh {
  std::string text;
  std::string message;
};

const BadMsh kBadMshs[] = {
    {"hello\n", "F:1: not a Gmsh MSH file (expected $MeshFormat, got 'hello')"},
    {"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n",
     "F:2: MSH version 2.2 is not supported; only 4.1 (export with 'gmsh -format msh41')"},
    {"$MeshFormat\n4.1 1 8\n", "F:2: binary MSH files are not supported; export ASCII (Gmsh option Mesh.Binary = 0)"},
    {std::string(kHeader) + "$Nodes\n1 1 1 1\n3 1 0 1\n1\n0 0 0\n", "F:8: section $Nodes has no $EndNodes"},
    {std::string(kHeader) + "$Comments\nno end\n", "F:5: section $Comments has no $EndComments"},
    {kHeader, "F: no tet4 (type 4) or hex8 (type 5) elements"},
    {std::string(kHeader) + "$Nodes\n1 2 1 2\n3 1 0 2\n1\n1\n0 0 0\n1 0 0\n$EndNodes\n",
     "F:8: node tag 1 appears twice"},
    {std::string(kHeader) + "$Nodes\n-1 2 1 2\n$EndNodes\n", "F:5: numEntityBlocks must be >= 0, got -1"},
    {std::string(kHeader) + "$Nodes\n1 3000000000 1 3000000000\n3 1 0 3000000000\n$EndNodes\n",
     "F:6: numNodesInBlock = 3000000000 is more than the file's 95 bytes can hold"},
    {kFiveNodes + "$Elements\n1 1 1 1\n3 1 4 2000000000\n$EndElements\n",
     "F:20: numElementsInBlock = 2000000000 is more than the file's 156 bytes can hold"},
    {kFiveNodes + "$Elements\n1 1 1 1\n3 1 4 1\n7 1 2 3 99\n$EndElements\n",
     "F:21: element 7 references node tag 99, which is not in $Nodes"},
    {kFiveNodes + "$Elements\n1 1 1 1\n3 1 5 1\n7 1 2 3 4\n$EndElements\n",
     "F:21: element 7 has 4 node tags, expected 8 for type 5 (hex8)"},
    {kFiveNodes + "$Elements\n1 1 1 1\n3 1 11 1\n7 1 2 3 4 5 1 2 3 4 5\n$EndElements\n",
     "F:20: 3D element type 11 is not supported (only 4 = tet4 and 5 = hex8)"},
    {std::string(kHeader) + kCube + "$Elements\n1 1 1 1\n3 1 4 1\n9 10 20 30 50\n$EndElements\n",
     "F:48: the file mixes tet4 and hex8 elements (a mesh has one element type)"},
    // Validation by ValidateMesh, with the file name as `what`.
    {kFiveNodes + "$Elements\n1 1 1 1\n3 1 4 1\n7 1 3 2 4\n$EndElements\n",
     "F: element 0 is inverted or degenerate (signed volume -0.166667 m^3)"},
};

TEST_F(ReadGmshTest, RejectsMalformedFilesNamingLineAndProblem) {
  for (const BadMsh& bad : kBadMshs) EXPECT_EQ(ErrorOf(bad.text), bad.message) << bad.text;
}

TEST_F(ReadGmshTest, RejectsPathsThatAreNotReadableFiles) {
  const std::string missing = directory_.File("missing.msh");
  const std::string folder = directory_.File("folder.msh");
  std::filesystem::create_directories(folder);
  const std::pair<std::string, std::string> cases[] = {
      {missing, "cannot open '" + missing + "'"},
      {folder, "cannot open '" + folder + "': it is a directory, not a file"},
  };
  for (const auto& [path, message] : cases) {
    EXPECT_THROW_MESSAGE(ReadGmsh(path), InvalidInputError, message);
  }
}

}  // namespace
}  // namespace diffpd
