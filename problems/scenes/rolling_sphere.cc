#include "scenes/rolling_sphere.h"

#include <random>

#include "diffpd/state_forces.h"
#include "diffpd/voxelizer.h"

namespace diffpd::problems {
namespace {

constexpr double kJitter = 1e-3;  // m
constexpr unsigned kJitterSeed = 2021;

}  // namespace

std::string RollingSphere::description() const {
  return "voxelised sphere (2469 DoFs) spinning on the ground, frictional contact, 100 steps of 5 ms (DiffPD Sec. "
         "6.2)";
}

Vec3 RollingSphere::Center(const Scene& scene) {
  // The voxel grid spans the sphere's bounding box (up to the jitter).
  return 0.5 * (scene.mesh.vertices.rowwise().minCoeff() + scene.mesh.vertices.rowwise().maxCoeff());
}

Scene RollingSphere::MakeScene() const {
  Scene scene;
  scene.mesh = VoxelizeSdf([](const Vec3& p) { return p.norm() - kRadius; }, Vec3::Constant(-kRadius),
                           Eigen::Vector3i::Constant(cells_), 2 * kRadius / cells_);
  std::mt19937 rng(kJitterSeed);
  std::uniform_real_distribution<double> jitter(-kJitter, kJitter);
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    for (int d = 0; d < 3; ++d) scene.mesh.vertices(d, i) += jitter(rng);
  scene.mesh.vertices.row(2).array() -= scene.mesh.vertices.row(2).minCoeff();
  scene.material.youngs_modulus = 2e6;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  const double center_z = Center(scene)(2);
  FrictionalContact ground;
  ground.surface = ContactSurface::Plane(Vec3(0, 0, 1), 0.0);
  for (const int i : BoundaryNodes(scene.mesh))
    if (scene.mesh.vertices(2, i) <= center_z) ground.nodes.push_back(i);
  scene.frictional_contacts = {ground};
  scene.frictional_contact_options.pd_linear_solve = linear_solve_;
  scene.frictional_contact_options.screening_rel_tolerance = kScreeningRelTolerance;
  return scene;
}

State RollingSphere::InitialState(const Simulator& sim) const {
  State s = sim.RestState();
  const Eigen::Matrix3Xd& v = sim.scene().mesh.vertices;
  const Vec3 center = Center(sim.scene());
  const Vec3 omega(0, kSpin, 0);
  for (int i = 0; i < v.cols(); ++i) s.v.segment<3>(3 * i) = omega.cross(Vec3(v.col(i)) - center);
  return s;
}

}  // namespace diffpd::problems
