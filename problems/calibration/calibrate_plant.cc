#include "calibration/calibrate_plant.h"

#include <array>
#include <cmath>
#include <set>

#include "diffpd/surface_mesh.h"
#include "diffpd/voxelizer.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

constexpr double kFineCell = 0.01;    // OBJ units
constexpr double kCoarseCell = 0.08;  // OBJ units
constexpr double kScale = 0.15;       // m per OBJ unit
constexpr double kDuration = 0.3;     // s
constexpr double kFrameRate = 30;     // Hz

double LowestZ(const Mesh& mesh) { return mesh.vertices.row(2).minCoeff(); }

}  // namespace

std::string PlantCalibration::description() const {
  return "recover E and nu of a voxelised potted plant swaying under gravity and a gust (DiffPD Sec. 7.1)";
}

Mesh PlantCalibration::PlantMesh() {
  const SurfaceMesh surface = ReadObj(SharedDataPath("meshes/plant.obj"));
  const Mesh fine = VoxelizeSurface(surface, kFineCell);
  std::set<std::array<int, 3>> occupied;
  for (int e = 0; e < fine.num_elements(); ++e) {
    Vec3 c = Vec3::Zero();
    for (int a = 0; a < 8; ++a) c += fine.vertices.col(fine.elements(a, e)) / 8;
    occupied.insert({static_cast<int>(std::floor(c(0) / kCoarseCell)), static_cast<int>(std::floor(c(1) / kCoarseCell)),
                     static_cast<int>(std::floor(c(2) / kCoarseCell))});
  }
  const Vec3 hi = surface.vertices.rowwise().maxCoeff();
  const Vec3 lo = surface.vertices.rowwise().minCoeff();
  Eigen::Vector3i lo_cell, cells;
  for (int d = 0; d < 3; ++d) {
    lo_cell(d) = static_cast<int>(std::floor(lo(d) / kCoarseCell));
    cells(d) = static_cast<int>(std::floor(hi(d) / kCoarseCell)) - lo_cell(d) + 1;
  }
  const double dx = kCoarseCell * kScale;
  return VoxelizeSdf(
      [&](const Vec3& p) {
        const std::array<int, 3> key = {static_cast<int>(std::floor(p(0) / dx)),
                                        static_cast<int>(std::floor(p(1) / dx)),
                                        static_cast<int>(std::floor(p(2) / dx))};
        return occupied.count(key) ? -1.0 : 1.0;
      },
      lo_cell.cast<double>() * dx, cells, dx);
}

Scene PlantCalibration::MakeScene() const {
  Scene scene;
  scene.mesh = PlantMesh();
  scene.material = truth();
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  const double z0 = LowestZ(scene.mesh);
  std::vector<int> pot;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) <= z0 + kCoarseCell * kScale * 1.001) pot.push_back(i);
  FixNodes(&scene, pot);
  return scene;
}

State PlantCalibration::InitialState(const Simulator& sim) const { return GustState(sim, Vec3(0.3, 0.15, 0)); }

State PlantCalibration::GustState(const Simulator& sim, const Vec3& gust) {
  State s = sim.RestState();
  const Mesh& mesh = sim.scene().mesh;
  const double z0 = LowestZ(mesh);
  const double height = mesh.vertices.row(2).maxCoeff() - z0;
  for (int i = 0; i < mesh.num_vertices(); ++i) s.v.segment<3>(3 * i) = gust * (mesh.vertices(2, i) - z0) / height;
  for (int d : sim.scene().dirichlet.dofs) s.v(d) = 0;
  return s;
}

std::vector<Marker> PlantCalibration::Markers(const Mesh& mesh) const {
  // The highest vertex and the extreme vertices along -x, +x, -y, +y among
  // those more than three cells above the lowest node (leaf tips).
  const double z_min = LowestZ(mesh) + 3 * kCoarseCell * kScale;
  int extreme[5] = {-1, -1, -1, -1, -1};
  auto better = [&](int candidate, int current, int axis, double sign) {
    return current < 0 || sign * mesh.vertices(axis, candidate) > sign * mesh.vertices(axis, current) + 1e-12;
  };
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    if (mesh.vertices(2, i) <= z_min) continue;
    if (better(i, extreme[0], 2, 1)) extreme[0] = i;
    if (better(i, extreme[1], 0, -1)) extreme[1] = i;
    if (better(i, extreme[2], 0, 1)) extreme[2] = i;
    if (better(i, extreme[3], 1, -1)) extreme[3] = i;
    if (better(i, extreme[4], 1, 1)) extreme[4] = i;
  }
  std::vector<Marker> markers;
  for (int v : extreme) {
    bool repeated = false;
    for (const Marker& m : markers) repeated = repeated || m.vertex == v;
    if (!repeated) markers.push_back(Marker{static_cast<int>(markers.size()), v, -1, Vec3::Zero(), 0});
  }
  return markers;
}

std::vector<double> PlantCalibration::CaptureTimes() const {
  std::vector<double> times;
  for (int k = 1; k / kFrameRate <= kDuration + 1e-12; ++k) times.push_back(k / kFrameRate);
  return times;
}

}  // namespace diffpd::problems
