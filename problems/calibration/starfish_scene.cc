#include "calibration/starfish_scene.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/tetgen_io.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

constexpr double kDensity = 400;             // kg/m^3
constexpr double kMuscleStiffness = 2e6;     // Pa
constexpr double kCentralHalfWidth = 0.018;  // m: the fixed central column, |y|, |z| < 18 mm
constexpr double kStripHalfWidth = 0.0075;   // m: an arm's central strip
constexpr double kFaceDistance = 0.001;      // m: flat-face layer / markers
// A muscle element has a face (>= 3 nodes) on the flat face: its fibre
// stretch along the arm is then the flat face's own stretch, so contraction
// shortens the face and curls the arm. (Elements with only 1-2 nodes there
// span the arm's thickness near the tips and shorten it without bending.)
constexpr int kMuscleFaceNodes = 3;
constexpr double kMarkerBand = 0.004;  // m: |z - target| of a marker candidate
constexpr std::array<double, 4> kMarkerTargetZ = {-0.070, -0.040, 0.0362, 0.0632};

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

const char* ToString(StarfishRegions regions) {
  switch (regions) {
    case StarfishRegions::kNone:
      return "none";
    case StarfishRegions::kBodyArms:
      return "body-arms";
  }
  return "unknown";
}

StarfishRegions ParseStarfishRegions(const std::string& name) {
  if (name == "body-arms") return StarfishRegions::kBodyArms;
  if (name == "none") return StarfishRegions::kNone;
  throw InvalidInputError("--regions = '" + name + "' is invalid: calibrate-starfish knows 'body-arms'");
}

Mesh StarfishMesh() {
  const SurfaceMesh surface = ReadObj(SharedDataPath("starfish/starfish_half_simplified.obj"));
  return TetrahedralizeSurface(surface, kStarfishTetgenSwitches);
}

std::array<int, 4> StarfishMarkerVertices(const Mesh& mesh) {
  std::array<int, 4> vertices;
  for (int m = 0; m < 4; ++m) {
    int best = -1;
    for (int i = 0; i < mesh.num_vertices(); ++i) {
      const Vec3 p = mesh.vertices.col(i);
      if (std::abs(p(0)) > kFaceDistance || std::abs(p(2) - kMarkerTargetZ[m]) > kMarkerBand) continue;
      if (best < 0 || p(1) < mesh.vertices(1, best)) best = i;
    }
    if (best < 0)
      throw InvalidInputError("starfish mesh: no vertex on the flat face within 4 mm of z = " + Num(kMarkerTargetZ[m]) +
                              " m for marker M" + std::to_string(m + 1));
    vertices[m] = best;
  }
  return vertices;
}

Scene MakeStarfishScene(StarfishRegions regions) {
  Scene scene;
  scene.mesh = StarfishMesh();
  scene.material = MaterialParameters{5e5, 0.4, kDensity};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  const Mesh& mesh = scene.mesh;
  std::vector<int> column;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (std::abs(mesh.vertices(1, i)) < kCentralHalfWidth && std::abs(mesh.vertices(2, i)) < kCentralHalfWidth)
      column.push_back(i);
  FixNodeAxes(&scene, column, {1, 2});
  // Muscles: -z arm, +z arm, -y arm, +y arm.
  scene.muscles.resize(4);
  for (int m = 0; m < 4; ++m) {
    scene.muscles[m].stiffness = kMuscleStiffness;
    scene.muscles[m].fibers = {m < 2 ? Vec3(0, 0, 1) : Vec3(0, 1, 0)};
  }
  for (int e = 0; e < mesh.num_elements(); ++e) {
    Vec3 c = Vec3::Zero();
    int on_face = 0;
    const int nodes = static_cast<int>(mesh.elements.rows());
    for (int a = 0; a < nodes; ++a) {
      const Vec3 p = mesh.vertices.col(mesh.elements(a, e));
      c += p / nodes;
      on_face += std::abs(p(0)) <= kFaceDistance;
    }
    if (on_face < kMuscleFaceNodes) continue;
    if (std::abs(c(1)) <= kStripHalfWidth && std::abs(c(2)) > kCentralHalfWidth)
      scene.muscles[c(2) < 0 ? 0 : 1].elements.push_back(e);
    else if (std::abs(c(2)) <= kStripHalfWidth && std::abs(c(1)) > kCentralHalfWidth)
      scene.muscles[c(1) < 0 ? 2 : 3].elements.push_back(e);
  }
  if (regions == StarfishRegions::kBodyArms) {
    MaterialRegion arms;
    for (int e = 0; e < mesh.num_elements(); ++e) {
      Vec3 c = Vec3::Zero();
      for (int a = 0; a < mesh.elements.rows(); ++a) c += mesh.vertices.col(mesh.elements(a, e)) / mesh.elements.rows();
      if (std::abs(c(1)) > kCentralHalfWidth || std::abs(c(2)) > kCentralHalfWidth) arms.elements.push_back(e);
    }
    arms.material = scene.material;
    scene.material_regions = {arms};
  }
  Hydrodynamics water;
  water.triangles = BoundaryTriangles(mesh);
  water.fluid_density = 1e3;
  water.drag_tangential = 0.05;
  water.drag_normal = 2.05;
  water.thrust = 0;
  scene.hydrodynamics = water;
  return scene;
}

}  // namespace diffpd::problems
