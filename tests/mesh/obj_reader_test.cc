#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "diffpd/surface_mesh.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd {
namespace {

class ReadObjTest : public ::testing::Test {
 protected:
  // Writes `text` to a file in the test's directory; returns its path.
  std::string Write(const std::string& name, const std::string& text) { return directory_.WriteFile(name, text); }

  // The message of ReadObj on a file holding `text`, "<path>" replaced by "F".
  std::string ErrorOf(const std::string& text) {
    const std::string path = Write("bad.obj", text);
    std::string message = testing::MessageOf<InvalidInputError>([&] { ReadObj(path); });
    if (message.rfind(path, 0) == 0) message = "F" + message.substr(path.size());
    return message;
  }

  const testing::TemporaryDirectory directory_{"diffpd-obj-reader"};
};

const char kTetrahedron[] =
    "# a tetrahedron\n"
    "mtllib none.mtl\n"
    "o tet\n"
    "v 0 0 0\n"
    "v 1.0 0 0   # trailing comment\n"
    "v 0 1e0 0\n"
    "v 0 0 +1 1.0\n"
    "vn 0 0 1\n"
    "vt 0 0\n"
    "s off\n"
    "f 1 3 2\n"
    "f 1/1 2/1 4/1\n"
    "f 1//1 4//1 3//1\n"
    "\n"
    "f -3/1/1 -2/1/1 -1/1/1\n";

TEST_F(ReadObjTest, ReadsVerticesFacesAndIndexForms) {
  const SurfaceMesh surface = ReadObj(Write("tet.obj", kTetrahedron));
  ASSERT_EQ(surface.vertices.cols(), 4);
  ASSERT_EQ(surface.triangles.cols(), 4);
  EXPECT_EQ(surface.vertices.col(3), Vec3(0, 0, 1));
  EXPECT_EQ(surface.triangles.col(0), Eigen::Vector3i(0, 2, 1));
  EXPECT_EQ(surface.triangles.col(3), Eigen::Vector3i(1, 2, 3));
  EXPECT_NO_THROW(ValidateWatertight(surface));
  EXPECT_NEAR(EnclosedVolume(surface), 1.0 / 6.0, 1e-15);
}

TEST_F(ReadObjTest, LinesOfOnlyFormFeedsOrVerticalTabsAreBlank) {
  // Such a line once left the reader with no token on a non-blank line
  // (a heap-use-after-free found by fuzz/fuzz_obj.cc).
  const SurfaceMesh surface =
      ReadObj(Write("blanks.obj", std::string("\f\nv 0 0 0\n \v \nv 1 0 0\f\nv 0 1 0\n") + "\f \t\r\nf 1 2 3\n\v\n"));
  ASSERT_EQ(surface.vertices.cols(), 3);
  ASSERT_EQ(surface.triangles.cols(), 1);
  EXPECT_EQ(surface.triangles.col(0), Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(ErrorOf("v 0 0 0\n\f\nv 1 0\n"), "F:3: expected x y z coordinates, got 'v 1 0'");
}

TEST_F(ReadObjTest, FanTriangulatesPolygons) {
  const SurfaceMesh surface =
      ReadObj(Write("pentagon.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 2 0\nv 0 1 0\nf 1 2 3 4 5\n"));
  ASSERT_EQ(surface.triangles.cols(), 3);
  EXPECT_EQ(surface.triangles.col(0), Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(surface.triangles.col(1), Eigen::Vector3i(0, 2, 3));
  EXPECT_EQ(surface.triangles.col(2), Eigen::Vector3i(0, 3, 4));
}

// A malformed OBJ text and the exact message, the path replaced by "F".
struct BadObj {
  const char* text;
  const char* message;
};

const BadObj kBadObjs[] = {
    {"v 0 0 0\nv 1 2\n", "F:2: expected x y z coordinates, got 'v 1 2'"},
    {"v 0 abc 0\n", "F:1: expected y coordinate (a finite number), got 'abc'"},
    {"v 0 nan 0\n", "F:1: expected y coordinate (a finite number), got 'nan'"},
    {"v 0 0 0\nv 1 0 0\nf 1 2\n", "F:3: a face needs at least 3 vertices, got 2"},
    {"v 0 0 0\nf 1 1 x\n", "F:2: malformed face entry 'x'"},
    {"v 0 0 0\nf 1 a/1 1\n", "F:2: malformed face entry 'a/1'"},
    {"v 0 0 0\nf 1 1/a 1\n", "F:2: malformed face entry '1/a'"},
    {"v 0 0 0\nf 1 1/ 1\n", "F:2: malformed face entry '1/'"},
    {"v 0 0 0\nf 1 1// 1\n", "F:2: malformed face entry '1//'"},
    {"v 0 0 0\nf 1 1/1/a 1\n", "F:2: malformed face entry '1/1/a'"},
    {"v 0 0 0\nf 1 1/1/1/1 1\n", "F:2: malformed face entry '1/1/1/1'"},
    {"v 0 0 0\nf 1 /1 1\n", "F:2: malformed face entry '/1'"},
    {"v 0 0 0\nf 1 0 1\n", "F:2: face index 0 is invalid (OBJ indices start at 1)"},
    {"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 12\nv 0 0 1\n", "F:5: face index 12 out of range (file has 4 vertices)"},
    {"v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", "F:3: face index -3 out of range (2 vertices read before this line)"},
    {"# nothing\n", "F: no vertices"},
    {"v 0 0 0\n", "F: no faces"},
};

TEST_F(ReadObjTest, RejectsMalformedFilesNamingLineAndProblem) {
  for (const BadObj& bad : kBadObjs) EXPECT_EQ(ErrorOf(bad.text), bad.message) << bad.text;
}

TEST_F(ReadObjTest, RejectsPathsThatAreNotReadableFiles) {
  const std::string missing = directory_.File("missing.obj");
  const std::string folder = directory_.File("folder.obj");
  std::filesystem::create_directories(folder);
  const std::pair<std::string, std::string> cases[] = {
      {missing, "cannot open '" + missing + "'"},
      {folder, "cannot open '" + folder + "': it is a directory, not a file"},
  };
  for (const auto& [path, message] : cases) {
    EXPECT_THROW_MESSAGE(ReadObj(path), InvalidInputError, message);
  }
}

TEST_F(ReadObjTest, AcceptsEveryDocumentedFaceEntryForm) {
  const SurfaceMesh surface = ReadObj(Write("forms.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2/7 3//-2\nf 3/1/1 2 -3\n"));
  ASSERT_EQ(surface.triangles.cols(), 2);
  EXPECT_EQ(surface.triangles.col(0), Eigen::Vector3i(0, 1, 2));
  EXPECT_EQ(surface.triangles.col(1), Eigen::Vector3i(2, 1, 0));
}

TEST_F(ReadObjTest, ForwardReferencesAreAllowed) {
  const SurfaceMesh surface = ReadObj(Write("forward.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"));
  EXPECT_EQ(surface.triangles.col(0), Eigen::Vector3i(0, 1, 2));
}

}  // namespace
}  // namespace diffpd
