#include "scenes/bouncing_ball.h"

#include "diffpd/state_forces.h"
#include "diffpd/voxelizer.h"

namespace diffpd::problems {

std::string BouncingBall::description() const {
  return "soft voxelised ball dropped on the ground, frictional contact, 150 steps of 2 ms (DiffPD Sec. 7.1)";
}

Scene BouncingBall::MakeScene() const {
  Scene scene;
  scene.mesh = VoxelizeSdf([](const Vec3& p) { return p.norm() - kRadius; }, Vec3::Constant(-kRadius),
                           Eigen::Vector3i::Constant(cells_), 2 * kRadius / cells_);
  scene.mesh.vertices.row(2).array() += kDropHeight - scene.mesh.vertices.row(2).minCoeff();
  scene.material.youngs_modulus = 5e5;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  scene.gravity = Vec3(0, 0, -9.81);
  FrictionalContact ground;
  ground.surface = ContactSurface::Plane(Vec3(0, 0, 1), 0.0);
  ground.nodes = BoundaryNodes(scene.mesh);
  scene.frictional_contacts = {ground};
  return scene;
}

State BouncingBall::InitialState(const Simulator& sim) const {
  State s = sim.RestState();
  for (int i = 0; i < s.v.size() / 3; ++i) s.v.segment<3>(3 * i) = Vec3(0.5, 0.0, -1.0);
  return s;
}

}  // namespace diffpd::problems
