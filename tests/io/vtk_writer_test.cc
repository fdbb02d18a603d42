#include "diffpd/vtk_writer.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "diffpd/box_mesh.h"
#include "diffpd/error.h"
#include "util/temporary_directory.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

int Count(const std::string& text, const std::string& pattern) {
  int count = 0;
  for (size_t pos = text.find(pattern); pos != std::string::npos; pos = text.find(pattern, pos + 1)) ++count;
  return count;
}

class VtkWriterTest : public ::testing::Test {
 protected:
  std::string Path(const std::string& name) const { return directory_.File(name); }

  const testing::TemporaryDirectory directory_{"diffpd-vtk-writer"};
};

Mesh TwoTets() {
  Mesh mesh;
  mesh.type = ElementType::kTet4;
  mesh.vertices.resize(3, 5);
  mesh.vertices << 0, 1, 0, 0, 1,  //
      0, 0, 1, 0, 1,               //
      0, 0, 0, 1, 1;
  mesh.elements.resize(4, 2);
  mesh.elements << 0, 1,  //
      1, 4,               //
      2, 2,               //
      3, 3;
  return mesh;
}

TEST_F(VtkWriterTest, HexMeshWithPointData) {
  const Mesh mesh = MakeBoxHexMesh(Eigen::Vector3i(2, 1, 1), Vec3(2.0, 1.0, 1.0));
  const Eigen::MatrixXd displacement = Eigen::MatrixXd::Constant(3, 12, 0.25);
  const Eigen::MatrixXd mass = Eigen::MatrixXd::Constant(1, 12, 2.0);
  WriteVtu(Path("box.vtu"), mesh, mesh.vertices, {{"displacement", displacement}, {"mass", mass}});
  const std::string text = ReadText(Path("box.vtu"));
  EXPECT_NE(text.find("<VTKFile type=\"UnstructuredGrid\""), std::string::npos);
  EXPECT_NE(text.find("NumberOfPoints=\"12\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"displacement\" NumberOfComponents=\"3\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"mass\" NumberOfComponents=\"1\""), std::string::npos);
  // Cell 0 is [0,1]^3: our nodes 0..7 at (i, j, k) = grid points (i*2 + j)*2 + k;
  // VTK's order is (0,0,0) (1,0,0) (1,1,0) (0,1,0) then the same at z = 1.
  EXPECT_NE(text.find("  0 4 6 2 1 5 7 3\n"), std::string::npos) << text;
  EXPECT_EQ(Count(text, "          12\n"), 2);                // two VTK_HEXAHEDRON cell types
  EXPECT_NE(text.find("          16\n"), std::string::npos);  // the second offset
}

TEST_F(VtkWriterTest, TetMesh) {
  const Mesh mesh = TwoTets();
  WriteVtu(Path("tets.vtu"), mesh, 2.0 * mesh.vertices);
  const std::string text = ReadText(Path("tets.vtu"));
  EXPECT_NE(text.find("NumberOfPoints=\"5\" NumberOfCells=\"2\""), std::string::npos);
  EXPECT_NE(text.find("  1 4 2 3\n"), std::string::npos);
  EXPECT_EQ(Count(text, "          10\n"), 2);           // VTK_TETRA; the offsets are 4 and 8
  EXPECT_NE(text.find("  2 2 2\n"), std::string::npos);  // scaled position of vertex 4
}

TEST_F(VtkWriterTest, Errors) {
  const Mesh mesh = TwoTets();
  auto message = [&](const std::string& path, const Eigen::Matrix3Xd& x, const VtkPointData& data) {
    return testing::MessageOf<InvalidInputError>([&] { WriteVtu(path, mesh, x, data); });
  };
  const std::string path = Path("e.vtu");
  EXPECT_EQ(message("/nonexistent-diffpd-dir/a.vtu", mesh.vertices, {}),
            "cannot write '/nonexistent-diffpd-dir/a.vtu'");
  EXPECT_EQ(message(path, Eigen::Matrix3Xd::Zero(3, 4), {}),
            "WriteVtu('" + path + "'): positions has 4 columns, the mesh has 5 vertices");
  EXPECT_EQ(message(path, mesh.vertices, {{"v", Eigen::MatrixXd::Zero(2, 5)}}),
            "WriteVtu('" + path + "'): point data 'v' is 2 x 5, must be 1 x 5 or 3 x 5");
  EXPECT_EQ(message(path, mesh.vertices, {{"a<b", Eigen::MatrixXd::Zero(1, 5)}}),
            "WriteVtu('" + path + "'): point data 'a<b' has an empty name or one with a character of \" & < > ' ,");
  EXPECT_EQ(message(path, mesh.vertices, {{"v", Eigen::MatrixXd::Zero(1, 5)}, {"v", Eigen::MatrixXd::Zero(1, 5)}}),
            "WriteVtu('" + path + "'): point data 'v' appears twice");
}

TEST_F(VtkWriterTest, PvdSeries) {
  const Mesh mesh = TwoTets();
  const std::string directory = Path("run/frames");  // created by the writer
  PvdWriter writer(directory, "tets");
  for (int f = 0; f < 3; ++f) {
    writer.AddFrame(0.01 * f, mesh, mesh.vertices, {{"f", Eigen::MatrixXd::Constant(1, 5, f)}});
  }
  writer.Write();
  EXPECT_EQ(writer.num_frames(), 3);
  for (const char* name : {"tets_0000.vtu", "tets_0001.vtu", "tets_0002.vtu"}) {
    EXPECT_TRUE(std::filesystem::exists(directory + "/" + name)) << name;
  }
  const std::string pvd = ReadText(directory + "/tets.pvd");
  EXPECT_NE(pvd.find("<VTKFile type=\"Collection\""), std::string::npos);
  EXPECT_EQ(Count(pvd, "<DataSet "), 3);
  EXPECT_NE(pvd.find("timestep=\"0\" group=\"\" part=\"0\" file=\"tets_0000.vtu\""), std::string::npos) << pvd;
  EXPECT_NE(pvd.find("timestep=\"0.02\" group=\"\" part=\"0\" file=\"tets_0002.vtu\""), std::string::npos) << pvd;
}

TEST_F(VtkWriterTest, PvdErrors) {
  std::ofstream(Path("file")) << "x";
  const std::string blocked = Path("file") + "/sub";
  const std::string blocked_message = testing::MessageOf<InvalidInputError>([&] { PvdWriter writer(blocked, "a"); });
  EXPECT_EQ(blocked_message.rfind("PvdWriter: cannot create directory '" + blocked + "'", 0), 0u) << blocked_message;
  EXPECT_THROW(PvdWriter(Path("d"), "a/b"), InvalidInputError);
  PvdWriter writer(Path("d"), "a");
  const Mesh mesh = TwoTets();
  writer.AddFrame(1.0, mesh, mesh.vertices);
  EXPECT_THROW_MESSAGE(writer.AddFrame(1.0, mesh, mesh.vertices), InvalidInputError,
                       "PvdWriter::AddFrame: time = 1 s, must be finite and > the previous frame's time 1 s");
}

}  // namespace
}  // namespace diffpd
