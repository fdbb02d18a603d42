#include "diffpd/mesh.h"

#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "diffpd/types.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

Mesh UnitTet() {
  Mesh mesh;
  mesh.type = ElementType::kTet4;
  mesh.vertices.resize(3, 4);
  mesh.vertices << 0, 1, 0, 0,  //
      0, 0, 1, 0,               //
      0, 0, 0, 1;
  mesh.elements.resize(4, 1);
  mesh.elements << 0, 1, 2, 3;
  return mesh;
}

// The cube [0,1]^3 as one hex: node a = 4i + 2j + k at (i, j, k).
Mesh UnitCube() {
  Mesh mesh;
  mesh.type = ElementType::kHex8;
  mesh.vertices.resize(3, 8);
  mesh.elements.resize(8, 1);
  for (int a = 0; a < 8; ++a) {
    mesh.vertices.col(a) = Vec3(a >> 2 & 1, a >> 1 & 1, a & 1);
    mesh.elements(a, 0) = a;
  }
  return mesh;
}

void ExpectMessage(const Mesh& mesh, const std::string& what, const std::string& expected) {
  EXPECT_THROW_MESSAGE(ValidateMesh(mesh, what), InvalidInputError, expected);
}

TEST(ElementTypeTest, NodesAndNames) {
  EXPECT_EQ(NodesPerElement(ElementType::kTet4), 4);
  EXPECT_EQ(NodesPerElement(ElementType::kHex8), 8);
  EXPECT_STREQ(ToString(ElementType::kTet4), "tet4");
  EXPECT_STREQ(ToString(ElementType::kHex8), "hex8");
}

TEST(SignedElementVolumeTest, UnitTetAndCube) {
  const Mesh tet = UnitTet();
  EXPECT_DOUBLE_EQ(SignedElementVolume(tet, tet.vertices, 0), 1.0 / 6.0);
  const Mesh cube = UnitCube();
  EXPECT_DOUBLE_EQ(SignedElementVolume(cube, cube.vertices, 0), 1.0);
  EXPECT_NO_THROW(ValidateMesh(tet));
  EXPECT_NO_THROW(ValidateMesh(cube));
}

TEST(SignedElementVolumeTest, AffineHexScalesByDeterminant) {
  Mesh cube = UnitCube();
  Mat3 a;
  a << 2.0, 0.3, 0.1,  //
      0.2, 1.5, -0.4,  //
      0.0, 0.5, 0.7;
  const Eigen::Matrix3Xd x = (a * cube.vertices).colwise() + Vec3(1.0, -2.0, 3.0);
  EXPECT_NEAR(SignedElementVolume(cube, x, 0), a.determinant(), 1e-14);
}

TEST(SignedElementVolumeTest, FrustumHexIsExact) {
  // Bottom square [0,1]^2 at z = 0, top square [-0.5,1.5]^2 at z = 1:
  // volume = h/3 (A1 + A2 + sqrt(A1 A2)) = (1 + 4 + 2)/3.
  Mesh cube = UnitCube();
  for (int a = 0; a < 8; ++a) {
    if (a & 1) cube.vertices.col(a).head<2>() = 2.0 * cube.vertices.col(a).head<2>() - Eigen::Vector2d(0.5, 0.5);
  }
  EXPECT_NEAR(SignedElementVolume(cube, cube.vertices, 0), 7.0 / 3.0, 1e-14);
  EXPECT_NO_THROW(ValidateMesh(cube));
}

TEST(SignedElementVolumeTest, UsesGivenPositions) {
  const Mesh tet = UnitTet();
  EXPECT_DOUBLE_EQ(SignedElementVolume(tet, 2.0 * tet.vertices, 0), 8.0 / 6.0);
}

// An integer cast to ElementType is refused before anything uses the type
// (NodesPerElement would abort).
TEST(ValidateMeshTest, UndeclaredElementType) {
  Mesh mesh = UnitCube();
  mesh.type = static_cast<ElementType>(7);
  ExpectMessage(mesh, "m", "m: type = 7 is invalid: must be ElementType::kTet4 (0) or kHex8 (1)");
}

TEST(ValidateMeshTest, NoElements) { ExpectMessage(Mesh{}, "mesh", "mesh: the mesh has no elements"); }

TEST(ValidateMeshTest, WrongNumberOfRows) {
  Mesh mesh = UnitCube();
  mesh.elements = mesh.elements.topRows(4).eval();
  ExpectMessage(mesh, "cube.msh", "cube.msh: elements must have 8 rows for hex8, got 4");
  Mesh tet = UnitTet();
  tet.type = ElementType::kHex8;
  ExpectMessage(tet, "m", "m: elements must have 8 rows for hex8, got 4");
}

TEST(ValidateMeshTest, NonFiniteCoordinate) {
  Mesh mesh = UnitTet();
  mesh.vertices(1, 2) = std::numeric_limits<double>::quiet_NaN();
  ExpectMessage(mesh, "m", "m: vertex 2 has a non-finite coordinate");
  mesh.vertices(1, 2) = std::numeric_limits<double>::infinity();
  ExpectMessage(mesh, "m", "m: vertex 2 has a non-finite coordinate");
}

TEST(ValidateMeshTest, IndexOutOfRange) {
  Mesh mesh = UnitTet();
  mesh.elements(3, 0) = 99;
  ExpectMessage(mesh, "m", "m: element 0 references vertex 99, but the mesh has 4 vertices");
  mesh.elements(3, 0) = -1;
  ExpectMessage(mesh, "m", "m: element 0 references vertex -1, but the mesh has 4 vertices");
}

TEST(ValidateMeshTest, RepeatedVertex) {
  Mesh mesh = UnitTet();
  mesh.elements(3, 0) = 1;
  ExpectMessage(mesh, "m", "m: element 0 repeats vertex 1");
}

TEST(ValidateMeshTest, InvertedTet) {
  Mesh mesh = UnitTet();
  mesh.vertices.col(3) = Vec3(0.0, 0.0, -9e-3);
  mesh.vertices.col(1) = Vec3(1e-2, 0.0, 0.0);
  mesh.vertices.col(2) = Vec3(0.0, 1e-2, 0.0);
  ExpectMessage(mesh, "bunny.ele", "bunny.ele: element 0 is inverted or degenerate (signed volume -1.5e-07 m^3)");
}

TEST(ValidateMeshTest, DegenerateTet) {
  Mesh mesh = UnitTet();
  mesh.vertices.col(3) = Vec3(0.3, 0.3, 0.0);  // flat
  ExpectMessage(mesh, "m", "m: element 0 is inverted or degenerate (signed volume 0 m^3)");
}

TEST(ValidateMeshTest, DegeneracyThresholdIsRelative) {
  Mesh mesh = UnitTet();
  mesh.vertices *= 1e-4;  // volume 1.7e-13 m^3, still well shaped
  EXPECT_NO_THROW(ValidateMesh(mesh));
  // Node 3 at height eps above the plane x + y + z = 1 through the other
  // three: V = eps / 6 against a bounding box of volume 1.
  mesh = UnitTet();
  mesh.vertices.col(0) = Vec3(1, 0, 0);
  mesh.vertices.col(1) = Vec3(0, 1, 0);
  mesh.vertices.col(2) = Vec3(0, 0, 1);
  mesh.vertices.col(3) = Vec3(0.25, 0.25, 0.5 + std::ldexp(1.0, -30));
  EXPECT_NO_THROW(ValidateMesh(mesh));
  mesh.vertices(2, 3) = 0.5 + std::ldexp(1.0, -45);  // V = 4.7e-15 <= 1e-12 V_bbox
  ExpectMessage(mesh, "m", "m: element 0 is inverted or degenerate (signed volume 4.73695e-15 m^3)");
}

TEST(ValidateMeshTest, MirroredHex) {
  Mesh mesh = UnitCube();
  mesh.vertices.row(0) *= -1.0;
  ExpectMessage(mesh, "m", "m: element 0 is inverted or degenerate (signed volume -1 m^3)");
}

TEST(ValidateMeshTest, HexWithNegativeJacobianAtAGaussPoint) {
  // Corner 7 pushed through the cube: total volume stays positive but det J
  // is negative at Gauss point 7 (the one nearest that corner).
  Mesh mesh = UnitCube();
  mesh.vertices.col(7) = Vec3(0.05, 0.05, 0.05);
  const double volume = SignedElementVolume(mesh, mesh.vertices, 0);
  ASSERT_GT(volume, 0.0);
  EXPECT_THROW_MESSAGE(
      ValidateMesh(mesh, "m"), InvalidInputError,
      "m: element 0 is inverted or degenerate (signed volume 0.2875 m^3; det J = -0.0965905 at Gauss point 7)");
}

TEST(ValidateMeshTest, UnreferencedVertex) {
  Mesh mesh = UnitTet();
  mesh.vertices.conservativeResize(3, 6);
  mesh.vertices.col(4) = Vec3(5, 5, 5);
  mesh.vertices.col(5) = Vec3(6, 6, 6);
  ExpectMessage(mesh, "m", "m: vertex 4 is not referenced by any element");
}

TEST(ValidateMeshTest, DefaultWhatIsMesh) {
  Mesh mesh = UnitTet();
  mesh.elements(0, 0) = 7;
  ExpectMessage(mesh, "mesh", "mesh: element 0 references vertex 7, but the mesh has 4 vertices");
  EXPECT_EQ(testing::MessageOf<InvalidInputError>([&] { ValidateMesh(mesh); }).rfind("mesh: ", 0), 0u);
}

}  // namespace
}  // namespace diffpd
