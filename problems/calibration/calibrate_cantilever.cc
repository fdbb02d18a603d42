#include "calibration/calibrate_cantilever.h"

#include <cmath>

#include "diffpd/box_mesh.h"

namespace diffpd::problems {
namespace {

const Vec3 kSize(0.2, 0.04, 0.04);  // m
constexpr double kTipTwist = M_PI / 4;
constexpr double kFrameRate = 30;  // Hz
constexpr int kFrames = 12;

// The vertex nearest to p (the markers sit on grid points).
int NearestVertex(const Mesh& mesh, const Vec3& p) {
  int best = 0;
  for (int i = 1; i < mesh.num_vertices(); ++i)
    if ((mesh.vertices.col(i) - p).squaredNorm() < (mesh.vertices.col(best) - p).squaredNorm()) best = i;
  return best;
}

}  // namespace

std::string CantileverCalibration::description() const {
  return "recover E and nu of a twisted beam released under gravity (generated mesh, data shipped in data/)";
}

Scene CantileverCalibration::MakeScene() const {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(10, 2, 2), kSize);
  scene.material = truth();
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  std::vector<int> clamped;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) <= 1e-9) clamped.push_back(i);
  FixNodes(&scene, clamped);
  return scene;
}

State CantileverCalibration::InitialState(const Simulator& sim) const {
  State s = sim.RestState();
  const double cy = kSize(1) / 2, cz = kSize(2) / 2;
  for (int i = 0; i < s.x.size() / 3; ++i) {
    const double angle = kTipTwist * s.x(3 * i) / kSize(0);
    const double y = s.x(3 * i + 1) - cy, z = s.x(3 * i + 2) - cz;
    s.x(3 * i + 1) = cy + std::cos(angle) * y - std::sin(angle) * z;
    s.x(3 * i + 2) = cz + std::sin(angle) * y + std::cos(angle) * z;
  }
  return s;
}

std::vector<Marker> CantileverCalibration::Markers(const Mesh& mesh) const {
  const double l = kSize(0), w = kSize(1), t = kSize(2);
  const Vec3 points[6] = {Vec3(l, 0, 0), Vec3(l, w, 0),     Vec3(l, 0, t),
                          Vec3(l, w, t), Vec3(l / 2, 0, t), Vec3(l / 2, w, t)};
  std::vector<Marker> markers;
  for (const Vec3& p : points)
    markers.push_back(Marker{static_cast<int>(markers.size()), NearestVertex(mesh, p), -1, Vec3::Zero(), 0});
  return markers;
}

std::vector<double> CantileverCalibration::CaptureTimes() const {
  std::vector<double> times;
  for (int k = 1; k <= kFrames; ++k) times.push_back(k / kFrameRate);
  return times;
}

}  // namespace diffpd::problems
