#include "scenes/cantilever.h"

#include <cmath>
#include <sstream>

#include "diffpd/box_mesh.h"

namespace diffpd::problems {

std::string Cantilever::description() const {
  std::ostringstream s;
  s << "twisted beam clamped at one end, " << nx_ << "x" << ny_ << "x" << nz_
    << " hexahedra, 25 steps of 10 ms (DiffPD Sec. 6.2)";
  return s.str();
}

Scene Cantilever::MakeScene() const {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(nx_, ny_, nz_), Vec3(0.32, 0.08, 0.08));
  scene.material.youngs_modulus = 1e6;
  scene.material.poissons_ratio = 0.45;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  std::vector<int> clamped;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) <= 1e-9) clamped.push_back(i);
  FixNodes(&scene, clamped);
  return scene;
}

State Cantilever::InitialState(const Simulator& sim) const {
  State s = sim.RestState();
  const double length = 0.32, cy = 0.04, cz = 0.04;
  for (int i = 0; i < s.x.size() / 3; ++i) {
    const double angle = (M_PI / 2) * s.x(3 * i) / length;
    const double y = s.x(3 * i + 1) - cy, z = s.x(3 * i + 2) - cz;
    s.x(3 * i + 1) = cy + std::cos(angle) * y - std::sin(angle) * z;
    s.x(3 * i + 2) = cz + std::sin(angle) * y + std::cos(angle) * z;
  }
  return s;
}

std::string FallingCube::description() const {
  return "free cube falling under gravity alone, released slightly squashed";
}

Scene FallingCube::MakeScene() const {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(cells_, cells_, cells_), Vec3(0.1, 0.1, 0.1));
  scene.material.youngs_modulus = 1e5;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.gravity = Vec3(0, 0, -9.81);
  return scene;
}

State FallingCube::InitialState(const Simulator& sim) const {
  State s = sim.RestState();
  for (int i = 0; i < s.x.size() / 3; ++i) s.x(3 * i + 2) *= 0.9;
  return s;
}

}  // namespace diffpd::problems
