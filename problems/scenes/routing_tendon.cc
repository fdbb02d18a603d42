#include "scenes/routing_tendon.h"

#include "diffpd/box_mesh.h"

namespace diffpd::problems {
namespace {

constexpr int kCellsXY = 3, kCellsZ = 12;
constexpr double kWidth = 0.03, kHeight = 0.12;

}  // namespace

std::string RoutingTendon::description() const {
  return "soft column clamped at its base, bent by four side muscles, 50 steps of 10 ms (DiffPD Sec. 7.2)";
}

Scene RoutingTendon::MakeScene() const {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(kCellsXY, kCellsXY, kCellsZ), Vec3(kWidth, kWidth, kHeight));
  scene.material.youngs_modulus = 1e5;
  scene.material.poissons_ratio = 0.45;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  std::vector<int> base;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) <= 1e-9) base.push_back(i);
  FixNodes(&scene, base);
  scene.muscles.resize(kMuscles);
  for (Muscle& m : scene.muscles) {
    m.fibers = {Vec3(0, 0, 1)};
    m.stiffness = 2e5;
  }
  // Element (i ny + j) nz + k is cell (i, j, k) (box_mesh.h).
  for (int i = 0; i < kCellsXY; ++i)
    for (int j = 0; j < kCellsXY; ++j)
      for (int k = 0; k < kCellsZ; ++k) {
        const int e = (i * kCellsXY + j) * kCellsZ + k;
        if (i == kCellsXY - 1) scene.muscles[0].elements.push_back(e);
        if (i == 0) scene.muscles[1].elements.push_back(e);
        if (j == kCellsXY - 1) scene.muscles[2].elements.push_back(e);
        if (j == 0) scene.muscles[3].elements.push_back(e);
      }
  return scene;
}

std::vector<StepInput> RoutingTendon::Inputs(const Simulator& sim, int steps) const {
  std::vector<StepInput> inputs(steps);
  for (int i = 0; i < steps; ++i) {
    inputs[i].activation = VectorXd::Ones(kMuscles);
    inputs[i].activation(0) = 1.0 - 0.2 * (i + 1) / steps;
  }
  return inputs;
}

std::vector<int> RoutingTendon::TipNodes(const Scene& scene) {
  std::vector<int> tip;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) >= kHeight - 1e-9) tip.push_back(i);
  return tip;
}

}  // namespace diffpd::problems
