#include "diffpd/box_mesh.h"

#include <string>

#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

TEST(MakeBoxHexMeshTest, CountsAndVolumes) {
  const Vec3 size(0.2, 0.3, 0.4);
  const Mesh mesh = MakeBoxHexMesh(Eigen::Vector3i(2, 3, 4), size, Vec3(1.0, -1.0, 0.5));
  EXPECT_EQ(mesh.type, ElementType::kHex8);
  EXPECT_EQ(mesh.num_vertices(), 3 * 4 * 5);
  EXPECT_EQ(mesh.num_elements(), 2 * 3 * 4);
  EXPECT_NO_THROW(ValidateMesh(mesh, "box"));
  double total = 0.0;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const double volume = SignedElementVolume(mesh, mesh.vertices, e);
    EXPECT_NEAR(volume, size.prod() / 24.0, 1e-15);
    total += volume;
  }
  EXPECT_NEAR(total, size.prod(), 1e-14);
}

TEST(MakeBoxHexMeshTest, NumberingConvention) {
  const Eigen::Vector3i cells(2, 3, 4);
  const Vec3 origin(1.0, -1.0, 0.5);
  const Vec3 h(0.1, 0.1, 0.1);
  const Mesh mesh = MakeBoxHexMesh(cells, cells.cast<double>().cwiseProduct(h), origin);
  for (int i = 0; i <= 2; ++i)
    for (int j = 0; j <= 3; ++j)
      for (int k = 0; k <= 4; ++k) {
        const Vec3 expected = origin + Vec3(i, j, k).cwiseProduct(h);
        EXPECT_TRUE(mesh.vertices.col((i * 4 + j) * 5 + k).isApprox(expected, 1e-14)) << i << j << k;
      }
  // Cell (1, 2, 3) is element (1 * 3 + 2) * 4 + 3; node a = 4 di + 2 dj + dk.
  const int e = (1 * 3 + 2) * 4 + 3;
  for (int a = 0; a < 8; ++a) {
    const Vec3 expected = origin + Vec3(1 + (a >> 2 & 1), 2 + (a >> 1 & 1), 3 + (a & 1)).cwiseProduct(h);
    EXPECT_TRUE(mesh.vertices.col(mesh.elements(a, e)).isApprox(expected, 1e-14)) << a;
  }
}

TEST(MakeBoxHexMeshTest, DefaultOriginIsZero) {
  const Mesh mesh = MakeBoxHexMesh(Eigen::Vector3i(1, 1, 1), Vec3(1.0, 2.0, 3.0));
  EXPECT_EQ(mesh.vertices.col(0), Vec3::Zero());
  EXPECT_EQ(mesh.vertices.col(7), Vec3(1.0, 2.0, 3.0));
}

TEST(MakeBoxHexMeshTest, RejectsBadInput) {
  auto message = [](const Eigen::Vector3i& cells, const Vec3& size) {
    return testing::MessageOf<InvalidInputError>([&] { MakeBoxHexMesh(cells, size); });
  };
  EXPECT_EQ(message(Eigen::Vector3i(1, 0, 1), Vec3::Ones()), "MakeBoxHexMesh: cells(1) = 0, must be >= 1");
  EXPECT_EQ(message(Eigen::Vector3i(1, 1, 1), Vec3(1.0, 1.0, -1.0)),
            "MakeBoxHexMesh: size(2) = -1 m, must be finite and > 0");
  EXPECT_EQ(message(Eigen::Vector3i(2000, 2000, 2000), Vec3::Ones()),
            "MakeBoxHexMesh: cells = (2000, 2000, 2000) is 8e+09 cells, more than the limit of 1e+08");
}

}  // namespace
}  // namespace diffpd
