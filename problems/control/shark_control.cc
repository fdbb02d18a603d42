#include "control/shark_control.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "diffpd/error.h"
#include "diffpd/quad_hydrodynamics.h"
#include "diffpd/voxelizer.h"

namespace diffpd::problems {
namespace {

constexpr double kLength = 2.0, kWidth = 0.2, kMuscleHalfHeight = 0.1;
constexpr double kMuscleStart = 0.1, kMuscleEnd = 1.5;

// Every bound below is a multiple of 0.1 m or lies between voxel centres, so
// that both resolutions (dx = 0.05, 0.1) keep the same cells whatever the
// rounding of the centres.

// Half-height of the trunk at x (0 beyond the trunk).
double TrunkHalfHeight(double x) {
  if (x < 0.1) return 0.075;
  if (x < 0.2) return 0.1;
  if (x < 1.4) return 0.15;
  if (x < 1.6) return 0.1;
  if (x < 1.7) return 0.075;
  return 0;
}

bool Inside(const Vec3& p) {
  const double x = p.x(), y = p.y(), z = p.z();
  if (x < 0 || x >= kLength || y < 0 || y > kWidth) return false;
  const bool mid = y > 0.04 && y < 0.16;  // the fins' thickness
  if (x < 1.7) {
    if (std::abs(z) < TrunkHalfHeight(x)) return true;
  } else if (mid && std::abs(z) < 0.1 + (2.0 / 3.0) * (x - 1.7)) {
    return true;  // tail fin
  }
  return mid && x >= 0.5 && x < 0.7 && z > 0.14 && z < 0.26;  // dorsal fin
}

Vec3 Centroid(const Mesh& mesh, int e) {
  Vec3 c = Vec3::Zero();
  for (int a = 0; a < 8; ++a) c += mesh.vertices.col(mesh.elements(a, e)) / 8;
  return c;
}

}  // namespace

std::string SharkControl::description() const {
  return "closed-loop swimming: a fish (3972 DoFs, 224 delay-line muscles in water; the water-snake template at the "
         "paper shark's scale) trained through the simulation with a 249-64-64-2 network (Adam)";
}

Swimmer SharkControl::MakeSwimmer(bool small) const {
  const double dx = small ? 0.1 : 0.05;
  const Vec3 origin(0, 0, -0.3);
  const Eigen::Vector3i cells(static_cast<int>(std::lround(kLength / dx)), static_cast<int>(std::lround(kWidth / dx)),
                              static_cast<int>(std::lround(0.6 / dx)));
  Swimmer s;
  s.scene.mesh = VoxelizeSdf([](const Vec3& c) { return Inside(c) ? -1.0 : 1.0; }, origin, cells, dx);
  const Mesh& mesh = s.scene.mesh;
  s.scene.material = MaterialParameters{1e6, 0.45, 1e3};
  s.scene.energies = {ElasticEnergy::kPdCorotated};
  QuadHydrodynamics water;
  water.quads = BoundaryQuads(mesh);
  s.scene.quad_hydrodynamics = water;

  // Strips: (side, layer) -> elements sorted head to tail.
  std::map<std::pair<int, long>, std::vector<std::pair<double, int>>> groups;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Vec3 c = Centroid(mesh, e);
    if (c.x() < kMuscleStart || c.x() >= kMuscleEnd || std::abs(c.z()) >= kMuscleHalfHeight) continue;
    const int side = c.y() < dx ? 0 : c.y() > kWidth - dx ? 1 : -1;
    if (side < 0) continue;
    groups[{side, std::lround(c.z() / (dx / 2))}].emplace_back(c.x(), e);
  }
  std::vector<MuscleStrip> strips;
  for (auto& [key, elements] : groups) {
    std::sort(elements.begin(), elements.end());
    MuscleStrip strip;
    strip.fiber = Vec3::UnitX();
    strip.stiffness = 1e5;
    for (const auto& [x, e] : elements) strip.elements.push_back(e);
    strips.push_back(strip);
    // Left (y = 0) contracts on -w, right on +w; lower layers channel 0, upper channel 1.
    s.drives.push_back(StripDrive{key.second < 0 ? 0 : 1, key.first == 0 ? -1 : 1});
  }
  s.strips = AddMuscleStrips(&s.scene, strips);
  s.channels = 2;

  // The mid-line nodes (x, 0.1, 0), head to tail.
  std::vector<std::pair<double, int>> midline;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3 p = mesh.vertices.col(v);
    if (std::abs(p.y() - kWidth / 2) < 1e-9 && std::abs(p.z()) < 1e-9) midline.emplace_back(p.x(), v);
  }
  std::sort(midline.begin(), midline.end());
  for (const auto& [x, v] : midline) {
    s.observation.nodes.push_back(v);
    if (std::abs(x - kLength / 2) < 1e-9) s.observation.reference_node = v;
  }
  DIFFPD_CHECK(static_cast<int>(midline.size()) == cells.x() + 1, "shark: " << midline.size() << " mid-line nodes");
  s.hidden_widths = {64, 64};
  s.loss.nodes = s.observation.nodes;
  s.loss.direction = -Vec3::UnitX();
  s.loss.side_weight = 10.0;
  s.steps = small ? 40 : 200;
  s.time_step = 3.33e-2;
  return s;
}

}  // namespace diffpd::problems
