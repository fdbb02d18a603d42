#include "diffpd/surface_mesh.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

// Outward-oriented unit cube [0,1]^3; vertex a = 4i + 2j + k at (i, j, k).
SurfaceMesh UnitCube() {
  SurfaceMesh surface;
  surface.vertices.resize(3, 8);
  for (int a = 0; a < 8; ++a) surface.vertices.col(a) = Vec3(a >> 2 & 1, a >> 1 & 1, a & 1);
  surface.triangles.resize(3, 12);
  surface.triangles << 0, 0, 4, 4, 0, 0, 2, 2, 0, 0, 1, 1,  //
      1, 3, 6, 7, 4, 5, 3, 7, 2, 6, 5, 7,                   //
      3, 2, 7, 5, 5, 1, 7, 6, 6, 4, 7, 3;
  return surface;
}

std::string WatertightError(const SurfaceMesh& surface) {
  return testing::MessageOf<InvalidInputError>([&] { ValidateWatertight(surface, "cube"); });
}

TEST(SurfaceMeshTest, CubeVolumeAndWindingNumber) {
  const SurfaceMesh cube = UnitCube();
  EXPECT_NO_THROW(ValidateWatertight(cube));
  EXPECT_NEAR(EnclosedVolume(cube), 1.0, 1e-15);
  EXPECT_NEAR(WindingNumber(cube, Vec3(0.5, 0.5, 0.5)), 1.0, 1e-12);
  EXPECT_NEAR(WindingNumber(cube, Vec3(0.9, 0.1, 0.2)), 1.0, 1e-12);
  EXPECT_NEAR(WindingNumber(cube, Vec3(1.5, 0.5, 0.5)), 0.0, 1e-12);
  EXPECT_NEAR(WindingNumber(cube, Vec3(-3.0, 7.0, 2.0)), 0.0, 1e-12);
}

TEST(SurfaceMeshTest, VolumeIsTranslationInvariantAndSigned) {
  SurfaceMesh cube = UnitCube();
  cube.vertices = (2.0 * cube.vertices).colwise() + Vec3(-5.0, 3.0, 10.0);
  EXPECT_NEAR(EnclosedVolume(cube), 8.0, 1e-12);
  cube.triangles.row(1).swap(cube.triangles.row(2));  // inward
  EXPECT_NEAR(EnclosedVolume(cube), -8.0, 1e-12);
  EXPECT_NEAR(WindingNumber(cube, Vec3(-4.0, 4.0, 11.0)), -1.0, 1e-12);
  EXPECT_NO_THROW(ValidateWatertight(cube));  // consistently (inward) oriented
}

TEST(SurfaceMeshTest, SharedSphere) {
  const SurfaceMesh sphere = ReadObj(DIFFPD_SHARED_DIR "/data/meshes/sphere.obj");
  EXPECT_NO_THROW(ValidateWatertight(sphere, "sphere.obj"));
  const double ball = 4.0 / 3.0 * std::acos(-1.0) * std::pow(0.03, 3);  // circumscribed ball
  EXPECT_LT(EnclosedVolume(sphere), ball);
  EXPECT_GT(EnclosedVolume(sphere), 0.9 * ball);
  EXPECT_NEAR(WindingNumber(sphere, Vec3(0.01, -0.005, 0.002)), 1.0, 1e-9);
  EXPECT_NEAR(WindingNumber(sphere, Vec3(0.04, 0.0, 0.0)), 0.0, 1e-9);
}

TEST(ValidateWatertightTest, Messages) {
  EXPECT_EQ(WatertightError(SurfaceMesh{}), "cube: the surface has no triangles");
  SurfaceMesh cube = UnitCube();
  cube.triangles(2, 3) = 99;
  EXPECT_EQ(WatertightError(cube), "cube: triangle 3 references vertex 99, but the surface has 8 vertices");
  cube = UnitCube();
  cube.triangles(2, 3) = 4;
  EXPECT_EQ(WatertightError(cube), "cube: triangle 3 repeats vertex 4");
  cube = UnitCube();
  cube.triangles.conservativeResize(3, 11);  // remove (1, 7, 3)
  EXPECT_EQ(WatertightError(cube), "cube: edge (1, 3) is used by 1 triangle(s); a closed surface needs exactly 2");
  cube = UnitCube();
  cube.triangles.col(11) = Eigen::Vector3i(1, 3, 7);  // flipped
  EXPECT_EQ(WatertightError(cube),
            "cube: edge (1, 3) has the same direction in triangles 0 and 11 (inconsistent orientation)");
}

TEST(ValidateWatertightTest, NonManifoldEdge) {
  SurfaceMesh cube = UnitCube();
  cube.triangles.conservativeResize(3, 14);
  cube.triangles.col(12) = Eigen::Vector3i(0, 7, 1);  // a fin through the cube, both sides
  cube.triangles.col(13) = Eigen::Vector3i(0, 1, 7);
  EXPECT_EQ(WatertightError(cube), "cube: edge (0, 1) is used by 4 triangle(s); a closed surface needs exactly 2");
}

}  // namespace
}  // namespace diffpd
