#include "control/bunny.h"

#include <sstream>

#include "diffpd/state_forces.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/voxelizer.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

const Vec3 kInitialGuess(0.3, 0.0, 1.0);  // m/s

}  // namespace

std::string Bunny::description() const {
  return "throw a soft bunny onto frictional ground: initial velocity to land its centre of mass on a target "
         "after clearing a wall (Ipopt)";
}

Scene Bunny::MakeScene(InstanceSize size) const {
  const SurfaceMesh surface = ReadObj(SharedDataPath("meshes/bunny_watertight_simplified.obj"));
  const Vec3 extent = surface.vertices.rowwise().maxCoeff() - surface.vertices.rowwise().minCoeff();
  Scene scene;
  scene.mesh = VoxelizeSurface(surface, size == InstanceSize::kSmall ? 0.02 : 0.0125, 0.1 / extent.maxCoeff());
  // Bottom 1 cm above the ground, x and y from 0.
  const Vec3 lo = scene.mesh.vertices.rowwise().minCoeff();
  scene.mesh.vertices.colwise() -= Vec3(lo.x(), lo.y(), lo.z() - 0.01);
  scene.material.youngs_modulus = 1e5;
  scene.material.poissons_ratio = 0.4;
  scene.material.density = 1e3;
  scene.gravity = Vec3(0, 0, -9.81);
  FrictionalContact ground;
  ground.surface = ContactSurface::Plane(Vec3::UnitZ(), 0.0);
  ground.nodes = BoundaryNodes(scene.mesh);
  scene.frictional_contacts.push_back(ground);
  return scene;
}

State Bunny::InitialState(const Simulator& sim) const {
  State s = sim.RestState();
  for (Eigen::Index i = 0; i < s.v.size() / 3; ++i) s.v.segment<3>(3 * i) = kInitialGuess;
  return s;
}

Ipopt::SmartPtr<solvers::RolloutNlp> Bunny::MakeNlp(const SolverOptions& options, InstanceSize size) const {
  using namespace solvers;
  const int K = steps(size);
  Ipopt::SmartPtr<RolloutNlp> nlp = new RolloutNlp(std::make_unique<RolloutFunction>(MakeScene(size), options, K));
  const Simulator& sim = nlp->function().simulator();
  const int n = sim.scene().mesh.num_vertices();
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  auto velocity = std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, all);
  velocity->SetBounds(-3.0, 3.0);
  velocity->SetInitial(kInitialGuess);
  nlp->AddVariables(std::move(velocity));
  const TrackedPoint com = CentreOfMass(sim.LumpedMass());
  const Vec3 target =
      com.At(nlp->function().base().initial.x) + Vec3(options_.target_offset.x(), options_.target_offset.y(), 0.0);
  nlp->AddObjective(
      std::make_unique<PointDistanceSquared>(com, kFinalState, target, "landing_error", Vec3(1.0, 1.0, 0.0)));
  nlp->AddConstraint(std::make_unique<PointCoordinate>(com, K / 4, Vec3::UnitZ(), "clear_wall"), options_.wall_height,
                     1e20);
  return nlp;
}

solvers::IpoptOptions Bunny::DefaultIpoptOptions(InstanceSize size) const {
  solvers::IpoptOptions o = TrajectoryOptimizationProblem::DefaultIpoptOptions(size);
  o.int_options = {{"max_iter", size == InstanceSize::kSmall ? 25 : 60}};
  o.num_options = {{"tol", 1e-7}, {"acceptable_tol", 1e-5}};
  return o;
}

}  // namespace diffpd::problems
