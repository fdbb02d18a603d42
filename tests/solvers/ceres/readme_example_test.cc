// Runs the README's example program (readme_example.cc) on a box surface and
// captured motion synthesised here from a known material, and checks that it
// recovers the material within 1%.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "diffpd/captured_motion.h"
#include "diffpd/simulator.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/voxelizer.h"
#include "util/readme_block.h"
#include "util/temporary_directory.h"

namespace diffpd {
namespace {

// A closed, outward-oriented box surface [0, 0.08] x [0, 0.02] x [0, 0.02] m.
void WriteBoxObj(const std::string& path) {
  std::ofstream out(path);
  const double l[3] = {0.08, 0.02, 0.02};
  for (int i = 0; i < 8; ++i)
    out << "v " << (i & 4 ? l[0] : 0) << " " << (i & 2 ? l[1] : 0) << " " << (i & 1 ? l[2] : 0) << "\n";
  // Quads (1-based, counterclockwise seen from outside), fan-triangulated by ReadObj.
  out << "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n";
}

TEST(ReadmeExampleTest, RecoversTheMaterialOfSyntheticCapturedMotion) {
  const testing::TemporaryDirectory dir("diffpd-readme-example");
  const std::string obj = dir.File("box.obj"), csv = dir.File("motion.csv");
  WriteBoxObj(obj);
  ValidateWatertight(ReadObj(obj), "box");
  // The example's scene with the true material.
  Scene scene;
  scene.mesh = VoxelizeSurface(ReadObj(obj), 0.01);
  ASSERT_EQ(scene.mesh.num_elements(), 32);  // 8 x 2 x 2 cells of 1 cm
  std::vector<int> clamped;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) < scene.mesh.vertices.row(0).minCoeff() + 1e-6) clamped.push_back(i);
  FixNodes(&scene, clamped);
  scene.gravity = Vec3(0, 0, -9.81);
  scene.material = MaterialParameters{2e5, 0.35, 1e3};
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  options.rel_tolerance = 1e-11;
  Simulator sim(scene, options);
  const Rollout truth = sim.Simulate(sim.RestState(), std::vector<StepInput>(25));
  // Markers: the far corners and a point inside the last element.
  std::vector<Marker> markers;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) > 0.08 - 1e-6)
      markers.push_back(Marker{static_cast<int>(markers.size()), i, -1, Vec3::Zero(), 0});
  markers.push_back(
      Marker{static_cast<int>(markers.size()), -1, scene.mesh.num_elements() - 1, Vec3(0.2, -0.3, 0.5), 0});
  std::vector<double> times;
  for (int f = 1; f <= 10; ++f) times.push_back(0.024 * f);
  WriteCapturedMotion(csv, SampleMarkers(scene.mesh, truth.states, 0.01, markers, times), "readme example");

  const std::string command = std::string(DIFFPD_README_EXAMPLE) + " " + obj + " " + csv + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  std::array<char, 512> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  ASSERT_EQ(pclose(pipe), 0) << output;
  const size_t at = output.rfind("E = ");
  ASSERT_NE(at, std::string::npos) << output;
  double e = 0, nu = 0;
  ASSERT_EQ(std::sscanf(output.c_str() + at, "E = %lf Pa, nu = %lf", &e, &nu), 2) << output;
  EXPECT_NEAR(e / 2e5, 1.0, 1e-2) << output;
  EXPECT_NEAR(nu / 0.35, 1.0, 1e-2) << output;
  EXPECT_NE(output.find("iter"), std::string::npos);  // Ceres' progress table
}

// The README's Ceres code block (after its marker) is a contiguous excerpt
// of the program compiled here, so the two cannot drift apart.
TEST(ReadmeExampleTest, ReadmeShowsAnExcerptOfTheExampleProgramVerbatim) {
  const std::string readme = testing::ReadTextFile(std::string(DIFFPD_SOURCE_DIR) + "/README.md");
  const std::string program =
      testing::ReadTextFile(std::string(DIFFPD_SOURCE_DIR) + "/tests/solvers/ceres/readme_example.cc");
  ASSERT_FALSE(program.empty());
  const std::string block = testing::CodeBlockAfter(readme, "<!-- The Ceres example");
  EXPECT_GT(block.size(), 200u) << "README.md has no Ceres example block, or it is nearly empty";
  EXPECT_NE(program.find(block), std::string::npos)
      << "README.md's Ceres block must be a verbatim excerpt of tests/solvers/ceres/readme_example.cc:\n"
      << block;
}

}  // namespace
}  // namespace diffpd
