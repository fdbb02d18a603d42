#include "diffpd/voxelizer.h"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "diffpd/box_mesh.h"
#include "diffpd/error.h"
#include "diffpd/surface_mesh.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

std::string ErrorOf(const std::function<void()>& call) { return testing::MessageOf<InvalidInputError>(call); }

double TotalVolume(const Mesh& mesh) {
  double total = 0.0;
  for (int e = 0; e < mesh.num_elements(); ++e) total += SignedElementVolume(mesh, mesh.vertices, e);
  return total;
}

// The closed surface of an axis-aligned box [lo, hi], outward oriented.
SurfaceMesh BoxSurface(const Vec3& lo, const Vec3& hi) {
  const Mesh box = MakeBoxHexMesh(Eigen::Vector3i(1, 1, 1), hi - lo, lo);
  SurfaceMesh surface;
  surface.vertices = box.vertices;  // node a = 4i + 2j + k
  surface.triangles.resize(3, 12);
  surface.triangles << 0, 0, 4, 4, 0, 0, 2, 2, 0, 0, 1, 1,  //
      1, 3, 6, 7, 4, 5, 3, 7, 2, 6, 5, 7,                   //
      3, 2, 7, 5, 5, 1, 7, 6, 6, 4, 7, 3;
  return surface;
}

// Octahedron |x| + |y| + |z| <= 1, outward oriented.
SurfaceMesh Octahedron() {
  SurfaceMesh surface;
  surface.vertices.resize(3, 6);
  surface.vertices << 1, -1, 0, 0, 0, 0,  //
      0, 0, 1, -1, 0, 0,                  //
      0, 0, 0, 0, 1, -1;
  surface.triangles.resize(3, 8);
  int t = 0;
  for (int sx = 0; sx < 2; ++sx)
    for (int sy = 0; sy < 2; ++sy)
      for (int sz = 0; sz < 2; ++sz) {
        const bool odd = (sx + sy + sz) % 2 == 1;
        const int x = sx, y = 2 + sy, z = 4 + sz;
        surface.triangles.col(t++) = odd ? Eigen::Vector3i(x, z, y) : Eigen::Vector3i(x, y, z);
      }
  return surface;
}

TEST(VoxelizeSdfTest, RollingSphereBenchmark) {
  const auto sphere = [](const Vec3& x) { return x.norm() - 0.05; };
  const Mesh mesh = VoxelizeSdf(sphere, Vec3::Constant(-0.05), Eigen::Vector3i(10, 10, 10), 0.01);
  EXPECT_EQ(mesh.num_elements(), 552);
  EXPECT_EQ(mesh.num_vertices(), 823);
  EXPECT_NO_THROW(ValidateMesh(mesh, "sphere"));
  EXPECT_NEAR(TotalVolume(mesh), 552e-6, 1e-15);
}

TEST(VoxelizeSdfTest, FullGridEqualsBoxMesh) {
  const auto everywhere = [](const Vec3&) { return -1.0; };
  const Eigen::Vector3i cells(3, 2, 4);
  const Vec3 origin(0.5, -0.25, 1.0);
  const Mesh voxels = VoxelizeSdf(everywhere, origin, cells, 0.25);
  const Mesh box = MakeBoxHexMesh(cells, 0.25 * cells.cast<double>(), origin);
  EXPECT_EQ(voxels.elements, box.elements);
  EXPECT_TRUE(voxels.vertices.isApprox(box.vertices, 1e-15));
}

TEST(VoxelizeSdfTest, DropsUnusedNodesAndNumbersInGridOrder) {
  // Two cells of a 3 x 1 x 1 grid, not touching: 16 nodes.
  const auto ends = [](const Vec3& x) { return std::abs(x(0) - 1.5) < 0.9 ? 1.0 : -1.0; };
  const Mesh mesh = VoxelizeSdf(ends, Vec3::Zero(), Eigen::Vector3i(3, 1, 1), 1.0);
  ASSERT_EQ(mesh.num_elements(), 2);
  ASSERT_EQ(mesh.num_vertices(), 16);
  for (int v = 1; v < 16; ++v) {
    const Vec3 a = mesh.vertices.col(v - 1), b = mesh.vertices.col(v);
    EXPECT_TRUE(a(0) < b(0) || (a(0) == b(0) && (a(1) < b(1) || (a(1) == b(1) && a(2) < b(2))))) << v;
  }
  EXPECT_EQ(mesh.vertices(0, mesh.elements(0, 1)), 2.0);
  EXPECT_NO_THROW(ValidateMesh(mesh));
}

// A call that must throw InvalidInputError, and its exact message.
struct Rejection {
  std::function<void()> call;
  std::string message;
};

void ExpectRejections(const std::vector<Rejection>& rejections) {
  for (const Rejection& r : rejections) EXPECT_EQ(ErrorOf(r.call), r.message);
}

TEST(VoxelizeSdfTest, RejectsBadInput) {
  const auto sphere = [](const Vec3& x) { return x.norm() - 0.05; };
  const auto nan = [](const Vec3&) { return std::numeric_limits<double>::quiet_NaN(); };
  const Eigen::Vector3i cells(4, 4, 4);
  ExpectRejections({
      {[&] { VoxelizeSdf(sphere, Vec3::Constant(1.0), cells, 0.01); }, "VoxelizeSdf: no cell centre has sdf < 0"},
      {[&] { VoxelizeSdf(sphere, Vec3::Zero(), cells, 0.0); }, "VoxelizeSdf: dx = 0, must be finite and > 0"},
      {[&] { VoxelizeSdf(sphere, Vec3::Zero(), Eigen::Vector3i(4, -1, 4), 0.01); },
       "VoxelizeSdf: cells(1) = -1, must be >= 1"},
      {[&] { VoxelizeSdf(nullptr, Vec3::Zero(), cells, 0.01); }, "VoxelizeSdf: sdf is empty"},
      {[&] { VoxelizeSdf(nan, Vec3::Zero(), Eigen::Vector3i(1, 1, 1), 1.0); },
       "VoxelizeSdf: sdf returned NaN at cell centre (0.5 0.5 0.5)"},
      {[&] { VoxelizeSdf(sphere, Vec3::Zero(), Eigen::Vector3i(100000, 100000, 100000), 1e-6); },
       "VoxelizeSdf: cells = (100000, 100000, 100000) is 1e+15 cells, more than the limit of 1e+08"},
  });
}

TEST(VoxelizeSurfaceTest, UnitCube) {
  const Mesh mesh = VoxelizeSurface(BoxSurface(Vec3::Zero(), Vec3::Ones()), 0.25);
  EXPECT_EQ(mesh.num_elements(), 64);
  EXPECT_EQ(mesh.num_vertices(), 125);
  EXPECT_NEAR(mesh.vertices.minCoeff(), 0.0, 1e-15);
  EXPECT_NEAR(mesh.vertices.maxCoeff(), 1.0, 1e-15);
}

TEST(VoxelizeSurfaceTest, ScaleAppliesAboutTheOrigin) {
  const Mesh mesh = VoxelizeSurface(BoxSurface(Vec3::Ones(), Vec3::Constant(2.0)), 1.0, 2.0);
  EXPECT_EQ(mesh.num_elements(), 8);
  EXPECT_NEAR(mesh.vertices.minCoeff(), 2.0, 1e-15);
  EXPECT_NEAR(mesh.vertices.maxCoeff(), 4.0, 1e-15);
}

TEST(VoxelizeSurfaceTest, OctahedronWithRaysThroughEdges) {
  // dx = 0.5: cell centres at +-0.25, +-0.75; z-rays through (0.25, 0.75)
  // graze the edge between (1,0,0) and (0,1,0). Inside: the 8 centres
  // (+-0.25, +-0.25, +-0.25).
  EXPECT_EQ(VoxelizeSurface(Octahedron(), 0.5).num_elements(), 8);
}

TEST(VoxelizeSurfaceTest, OctahedronWithRaysThroughVertices) {
  // dx = 2/3: centres at -2/3, 0, 2/3; the axis rays hit the six vertices.
  // Inside: the centre cell and its 6 face neighbours.
  EXPECT_EQ(VoxelizeSurface(Octahedron(), 2.0 / 3.0).num_elements(), 7);
}

TEST(VoxelizeSurfaceTest, SphereVolumeMatchesSurface) {
  const SurfaceMesh sphere = ReadObj(DIFFPD_SHARED_DIR "/data/meshes/sphere.obj");
  const double dx = 0.002;  // radius 0.03: 30 cells across
  const Mesh mesh = VoxelizeSurface(sphere, dx);
  EXPECT_NO_THROW(ValidateMesh(mesh, "voxelized sphere"));
  EXPECT_NEAR(TotalVolume(mesh) / EnclosedVolume(sphere), 1.0, 0.02);
  // Every kept cell centre is inside by the winding number, and the kept
  // count equals the number of inside centres.
  int inside_cells = 0;
  // The grid of VoxelizeSurface: centred on the bounding box.
  const Vec3 box_lo = sphere.vertices.rowwise().minCoeff(), box_hi = sphere.vertices.rowwise().maxCoeff();
  const Eigen::Vector3i cells = ((box_hi - box_lo) / dx).array().ceil().cast<int>();
  const Vec3 lo = (box_lo + box_hi - dx * cells.cast<double>()) / 2.0;
  for (int i = 0; i < cells(0); ++i)
    for (int j = 0; j < cells(1); ++j)
      for (int k = 0; k < cells(2); ++k) {
        inside_cells += WindingNumber(sphere, lo + dx * Vec3(i + 0.5, j + 0.5, k + 0.5)) > 0.5;
      }
  EXPECT_EQ(inside_cells, mesh.num_elements());
  for (int e = 0; e < mesh.num_elements(); ++e) {
    Vec3 centre = Vec3::Zero();
    for (int a = 0; a < 8; ++a) centre += mesh.vertices.col(mesh.elements(a, e)) / 8.0;
    ASSERT_GT(WindingNumber(sphere, centre), 0.5) << e;
  }
}

TEST(VoxelizeSurfaceTest, RejectsBadInput) {
  SurfaceMesh triangle;  // open: three boundary edges
  triangle.vertices.resize(3, 3);
  triangle.vertices << 0, 1, 0,  //
      0, 0, 1,                   //
      0, 0, 0;
  triangle.triangles.resize(3, 1);
  triangle.triangles << 0, 1, 2;
  SurfaceMesh bad_index = triangle;
  bad_index.triangles(2, 0) = 3;
  SurfaceMesh open_box = BoxSurface(Vec3::Zero(), Vec3::Ones());  // the box without its last triangle
  open_box.triangles.conservativeResize(3, 11);
  SurfaceMesh flat;  // closed but of zero volume
  flat.vertices.resize(3, 4);
  flat.vertices << 0, 1, 0, 1,  //
      0, 0, 1, 1,               //
      0, 0, 0, 0;
  flat.triangles.resize(3, 4);
  flat.triangles << 0, 0, 0, 1,  //
      2, 1, 3, 2,                //
      1, 3, 2, 3;
  const SurfaceMesh box = BoxSurface(Vec3::Zero(), Vec3(1, 1, 0.5));
  ExpectRejections({
      {[&] { VoxelizeSurface(flat, 0.5); },
       "VoxelizeSurface: no cell centre lies inside the surface (dx = 0.5, grid 2 x 2 x 1 cells); "
       "use a smaller dx or check that the surface is closed"},
      {[&] { VoxelizeSurface(box, -0.5); }, "VoxelizeSurface: dx = -0.5, must be finite and > 0"},
      {[&] { VoxelizeSurface(box, 0.5, 0.0); }, "VoxelizeSurface: scale = 0, must be finite and > 0"},
      {[&] { VoxelizeSurface(box, 1e-5); },
       "VoxelizeSurface: cells = (100000, 100000, 50000) is 5e+14 cells, more than the limit of 1e+08 (dx = 1e-05 "
       "for a bounding box of size (  1   1 0.5))"},
      {[&] { VoxelizeSurface(bad_index, 0.5); },
       "VoxelizeSurface: triangle 0 references vertex 3, but the surface has 3 vertices"},
      {[&] { VoxelizeSurface(SurfaceMesh{}, 0.5); }, "VoxelizeSurface: the surface has no triangles"},
      {[&] { VoxelizeSurface(triangle, 0.5); },
       "VoxelizeSurface: the surface is not closed: 3 boundary edges, the first (0, 1) (a closed surface has every "
       "edge in an even number of triangles)"},
      {[&] { VoxelizeSurface(open_box, 0.5); },
       "VoxelizeSurface: the surface is not closed: 3 boundary edges, the first (1, 3) (a closed surface has every "
       "edge in an even number of triangles)"},
  });
}

// Surfaces that meet themselves along an edge (four triangles there, as in
// the shared plant and cow meshes) are closed: the parity of ray crossings
// still separates inside from outside.
TEST(VoxelizeSurfaceTest, AcceptsClosedSurfacesTouchingAlongAnEdge) {
  SurfaceMesh two = BoxSurface(Vec3::Zero(), Vec3::Ones());
  const SurfaceMesh other = BoxSurface(Vec3(1, 1, 0), Vec3(2, 2, 1));  // shares the edge x = y = 1
  two.vertices.conservativeResize(3, 16);
  two.vertices.rightCols(8) = other.vertices;
  two.triangles.conservativeResize(3, 24);
  two.triangles.rightCols(12) = other.triangles.array() + 8;
  // Weld the shared edge's two corners so that the edge is in four triangles.
  for (int t = 12; t < 24; ++t)
    for (int c = 0; c < 3; ++c) {
      if (two.triangles(c, t) == 8) two.triangles(c, t) = 6;  // (1, 1, 0)
      if (two.triangles(c, t) == 9) two.triangles(c, t) = 7;  // (1, 1, 1)
    }
  const Mesh mesh = VoxelizeSurface(two, 0.25);
  EXPECT_NEAR(TotalVolume(mesh), 2.0, 1e-12);
}

}  // namespace
}  // namespace diffpd
