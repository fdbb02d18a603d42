#include "diffpd/tetgen_io.h"

#include <stdlib.h>

#include <stdexcept>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "diffpd/surface_mesh.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"
#include "mesh/subprocess.h"

namespace diffpd {
namespace {

// Two tets sharing the face (1, 2, 3) (1-based), with attributes, boundary
// markers and comments.
const char kNodes1[] =
    "# five points\n"
    "5 3 1 1\n"
    "1  0 0 0   7.5 1\n"
    "2  1 0 0   7.5 1  # marker\n"
    "3  0 1 0   7.5 0\n"
    "\n"
    "4  0 0 1   7.5 1\n"
    "5  1 1 1   7.5 1\n";
const char kEle1[] =
    "2 4 1\n"
    "1  1 2 3 4  10\n"
    "2  2 5 3 4  10  # second\n";

class TetGenTest : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& text) { return directory_.WriteFile(name, text); }

  // The message of ReadTetGen on the two texts, with the paths replaced by
  // "N" and "E".
  std::string ErrorOf(const std::string& nodes, const std::string& elements) {
    const std::string node_path = Write("m.node", nodes), ele_path = Write("m.ele", elements);
    std::string message = testing::MessageOf<InvalidInputError>([&] { ReadTetGen(node_path, ele_path); });
    if (message.rfind(node_path, 0) == 0) message = "N" + message.substr(node_path.size());
    if (message.rfind(ele_path, 0) == 0) message = "E" + message.substr(ele_path.size());
    return message;
  }

  const testing::TemporaryDirectory directory_{"diffpd-tetgen-io"};
};

TEST_F(TetGenTest, ReadsOneBasedFiles) {
  const Mesh mesh = ReadTetGen(Write("a.node", kNodes1), Write("a.ele", kEle1));
  EXPECT_EQ(mesh.type, ElementType::kTet4);
  ASSERT_EQ(mesh.num_vertices(), 5);
  ASSERT_EQ(mesh.num_elements(), 2);
  EXPECT_EQ(mesh.vertices.col(4), Vec3(1, 1, 1));
  EXPECT_EQ(mesh.elements.col(1), Eigen::Vector4i(1, 4, 2, 3));
  EXPECT_DOUBLE_EQ(SignedElementVolume(mesh, mesh.vertices, 0), 1.0 / 6.0);
  EXPECT_DOUBLE_EQ(SignedElementVolume(mesh, mesh.vertices, 1), 1.0 / 3.0);
}

TEST_F(TetGenTest, ReadsZeroBasedFiles) {
  const Mesh mesh = ReadTetGen(Write("b.node", "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n4 1 1 1\n"),
                               Write("b.ele", "2 4 0\n0 0 1 2 3\n1 1 4 2 3\n"));
  EXPECT_EQ(mesh.elements.col(0), Eigen::Vector4i(0, 1, 2, 3));
  EXPECT_EQ(mesh.elements.col(1), Eigen::Vector4i(1, 4, 2, 3));
}

// A malformed .node/.ele pair and the exact message, the paths replaced by
// "N" and "E".
struct BadTetGen {
  std::string nodes;
  std::string elements;
  std::string message;
};

const BadTetGen kBadTetGens[] = {
    {"5 2 0 0\n", kEle1, "N:1: expected dimension 3, got 2"},
    {"x 3 0 0\n", kEle1, "N:1: expected the number of points, got 'x'"},
    {"-2 3 0 0\n", kEle1, "N:1: the number of points must be >= 0, got -2"},
    {"1000000000 3 0 0\n1 0 0 0\n", kEle1,
     "N:1: the number of points = 1000000000 is more than the file's 25 bytes can hold"},
    {"99999999999999 3 0 0\n", kEle1,
     "N:1: the number of points = 99999999999999 is more than the file's 21 bytes can hold"},
    {"2 3 0 0\n5 0 0 0\n", kEle1, "N:2: first point number must be 0 or 1, got 5"},
    {"3 3 0 0\n1 0 0 0\n2 1 0 0\n4 0 1 0\n", kEle1, "N:4: point number 4 out of sequence (expected 3)"},
    {"5 3 0 0\n1 0 0 0\n2 1 0 0\n", kEle1, "N: file ends after 2 of 5 points"},
    {"1 3 0 0\n1 0 0\n", kEle1, "N:2: expected z coordinate, got end of line"},
    {kNodes1, "2 10 0\n", "E:1: only 4-node tetrahedra are supported, got 10 nodes per tetrahedron"},
    {kNodes1, "4000000000 4 0\n",
     "E:1: the number of tetrahedra = 4000000000 is more than the file's 15 bytes can hold"},
    {kNodes1, "2 4 0\n1 1 2 3 4\n2 2 5 3 9\n", "E:3: node 9 out of range (the .node file numbers its 5 points 1..5)"},
    {kNodes1, "2 4 0\n1 1 2 3 4\n", "E: file ends after 1 of 2 tetrahedra"},
    {kNodes1, "2 4 0\n1 1 2 3 4\n3 2 5 3 4\n", "E:3: tetrahedron number 3 out of sequence (expected 2)"},
    // Validation by ValidateMesh, with the .ele path as `what`.
    {kNodes1, "2 4 0\n1 1 2 3 4\n2 2 3 5 4\n", "E: element 1 is inverted or degenerate (signed volume -0.333333 m^3)"},
    {kNodes1, "1 4 0\n1 1 2 3 4\n", "E: vertex 4 is not referenced by any element"},
};

TEST_F(TetGenTest, RejectsMalformedFilesNamingLineAndProblem) {
  for (const BadTetGen& bad : kBadTetGens)
    EXPECT_EQ(ErrorOf(bad.nodes, bad.elements), bad.message) << bad.nodes << "---\n" << bad.elements;
}

TEST_F(TetGenTest, RejectsPathsThatAreNotReadableFiles) {
  const std::string missing = directory_.File("missing.node");
  const std::string folder = directory_.File("folder.node");
  std::filesystem::create_directories(folder);
  const std::string nodes = Write("ok.node", kNodes1);
  struct Case {
    std::string node_path, ele_path, message;
  };
  const Case cases[] = {
      {missing, missing, "cannot open '" + missing + "'"},
      {folder, folder, "cannot open '" + folder + "': it is a directory, not a file"},
      {nodes, folder, "cannot open '" + folder + "': it is a directory, not a file"},
  };
  for (const Case& c : cases) {
    EXPECT_THROW_MESSAGE(ReadTetGen(c.node_path, c.ele_path), InvalidInputError, c.message);
  }
}

bool HaveTetGen() { return !internal::FindOnPath("tetgen").empty(); }

TEST(TetrahedralizeSurfaceTest, SphereVolumeMatchesSurface) {
  if (!HaveTetGen()) GTEST_SKIP() << "the tetgen program is not installed";
  const SurfaceMesh sphere = ReadObj(DIFFPD_SHARED_DIR "/data/meshes/sphere.obj");
  const Mesh mesh = TetrahedralizeSurface(sphere);
  EXPECT_EQ(mesh.type, ElementType::kTet4);
  EXPECT_NO_THROW(ValidateMesh(mesh));
  EXPECT_GE(mesh.num_vertices(), sphere.vertices.cols());
  double volume = 0.0;
  for (int e = 0; e < mesh.num_elements(); ++e) volume += SignedElementVolume(mesh, mesh.vertices, e);
  EXPECT_NEAR(volume / EnclosedVolume(sphere), 1.0, 0.01);

  const Mesh scaled = TetrahedralizeSurface(sphere, "pq1.414Y", 2.0);
  double scaled_volume = 0.0;
  for (int e = 0; e < scaled.num_elements(); ++e) scaled_volume += SignedElementVolume(scaled, scaled.vertices, e);
  EXPECT_NEAR(scaled_volume / (8.0 * EnclosedVolume(sphere)), 1.0, 0.01);
}

TEST(TetrahedralizeSurfaceTest, Errors) {
  const SurfaceMesh sphere = ReadObj(DIFFPD_SHARED_DIR "/data/meshes/sphere.obj");
  auto message = [&](const SurfaceMesh& surface, const std::string& switches, double scale) {
    return testing::MessageOf<std::exception>([&] { TetrahedralizeSurface(surface, switches, scale); });
  };
  EXPECT_EQ(message(sphere, "-pq", 1.0),
            "TetrahedralizeSurface: switches '-pq' must be one word without '-' or spaces, e.g. \"pq1.414Y\"");
  EXPECT_EQ(message(sphere, "pqN", 1.0),
            "TetrahedralizeSurface: switch 'N' in 'pqN' is not supported (it changes the files TetGen reads or "
            "writes)");
  EXPECT_EQ(message(sphere, "pq", -1.0), "TetrahedralizeSurface: scale = -1, must be finite and > 0");
  EXPECT_EQ(message(SurfaceMesh{}, "pq", 1.0), "TetrahedralizeSurface: the surface has no triangles");
  SurfaceMesh broken = sphere;
  broken.triangles(1, 5) = 162;
  EXPECT_EQ(message(broken, "pq", 1.0),
            "TetrahedralizeSurface: triangle 5 references vertex 162, but the surface has 162 vertices");

  const std::string path = getenv("PATH") ? getenv("PATH") : "";
  setenv("PATH", "/nonexistent-diffpd-dir", 1);
  EXPECT_EQ(message(sphere, "pq", 1.0), "tetgen program not found: install the Debian package 'tetgen'");
  setenv("PATH", path.c_str(), 1);

  SurfaceMesh triangle;  // an open surface: refused before TetGen runs
  triangle.vertices.resize(3, 3);
  triangle.vertices << 0, 1, 0,  //
      0, 0, 1,                   //
      0, 0, 0;
  triangle.triangles.resize(3, 1);
  triangle.triangles << 0, 1, 2;
  EXPECT_EQ(message(triangle, "pq1.414Y", 1.0),
            "TetrahedralizeSurface: the surface is not closed: 3 boundary edges, the first (0, 1) (a closed surface "
            "has every edge in an even number of triangles)");

  if (!HaveTetGen()) GTEST_SKIP() << "the tetgen program is not installed";
  SurfaceMesh flat;  // closed but of zero volume: TetGen gives up
  flat.vertices.resize(3, 4);
  flat.vertices << 0, 1, 0, 1,  //
      0, 0, 1, 1,               //
      0, 0, 0, 0;
  flat.triangles.resize(3, 4);
  flat.triangles << 0, 0, 0, 1,  //
      2, 1, 3, 2,                //
      1, 3, 2, 3;
  const std::string failure = message(flat, "pq1.414Y", 1.0);
  EXPECT_EQ(failure.rfind("tetgen failed (", 0), 0u) << failure;
  EXPECT_NE(failure.find(") with switches 'pq1.414Y': "), std::string::npos) << failure;
}

}  // namespace
}  // namespace diffpd
