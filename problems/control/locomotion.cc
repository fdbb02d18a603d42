#include "control/locomotion.h"

#include <cmath>

#include "diffpd/solvers/core/activation_block.h"
#include "diffpd/solvers/ipopt/linear_constraint.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "diffpd/state_forces.h"
#include "diffpd/surface_mesh.h"
#include "diffpd/voxelizer.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

Vec3 Centroid(const Mesh& mesh, int e) {
  Vec3 c = Vec3::Zero();
  for (int a = 0; a < mesh.elements.rows(); ++a) c += mesh.vertices.col(mesh.elements(a, e));
  return c / mesh.elements.rows();
}

// Moves the mesh so that its lowest point is 1 mm above the ground and its
// x and y start at 0.
void PlaceOnGround(Mesh* mesh) {
  const Vec3 lo = mesh->vertices.rowwise().minCoeff();
  mesh->vertices.colwise() -= Vec3(lo.x(), lo.y(), lo.z() - 0.001);
}

double Box(const Vec3& p, const Vec3& lo, const Vec3& hi) {
  const Vec3 q = (p - (lo + hi) / 2).cwiseAbs() - (hi - lo) / 2;
  return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
}

Mesh QuadrupedMesh(double dx) {
  auto sdf = [](const Vec3& p) {
    double d = Box(p, Vec3(0, 0, 0.03), Vec3(0.12, 0.06, 0.06));
    for (double x : {0.0, 0.09})
      for (double y : {0.0, 0.03}) d = std::min(d, Box(p, Vec3(x, y, 0), Vec3(x + 0.03, y + 0.03, 0.03)));
    return d;
  };
  const Eigen::Vector3i cells(std::lround(0.12 / dx), std::lround(0.06 / dx), std::lround(0.06 / dx));
  Mesh mesh = VoxelizeSdf(sdf, Vec3::Zero(), cells, dx);
  PlaceOnGround(&mesh);
  return mesh;
}

// Legs: elements whose centre is below `leg_height`, one muscle per
// quadrant of the legs' footprint (x front/back, y left/right), split into
// front and back halves of each leg when `split`. Fibres vertical.
std::vector<Muscle> LegMuscles(const Mesh& mesh, double leg_height, bool split) {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  std::vector<int> legs;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Vec3 c = Centroid(mesh, e);
    if (c.z() >= leg_height) continue;
    legs.push_back(e);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const Vec3 mid = (lo + hi) / 2;
  // Centre of each leg in x, for the front/back split.
  double leg_x[4] = {0, 0, 0, 0};
  int count[4] = {0, 0, 0, 0};
  auto quadrant = [&](const Vec3& c) { return (c.x() > mid.x() ? 2 : 0) + (c.y() > mid.y() ? 1 : 0); };
  for (int e : legs) {
    const int q = quadrant(Centroid(mesh, e));
    leg_x[q] += Centroid(mesh, e).x();
    ++count[q];
  }
  std::vector<Muscle> muscles(split ? 8 : 4);
  for (int e : legs) {
    const Vec3 c = Centroid(mesh, e);
    const int q = quadrant(c);
    const int m = split ? 2 * q + (c.x() > leg_x[q] / count[q] ? 1 : 0) : q;
    muscles[m].elements.push_back(e);
  }
  std::vector<Muscle> used;
  for (Muscle& m : muscles)
    if (!m.elements.empty()) {
      m.fibers = {Vec3::UnitZ()};
      m.stiffness = 2e5;
      used.push_back(std::move(m));
    }
  return used;
}

// Ring sectors of a wheel in the x-z plane, fibres along the ring.
std::vector<Muscle> RingMuscles(const Mesh& mesh, int sectors) {
  const Vec3 centre = (mesh.vertices.rowwise().minCoeff() + mesh.vertices.rowwise().maxCoeff()) / 2;
  std::vector<Muscle> muscles(sectors);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Vec3 r = Centroid(mesh, e) - centre;
    const double angle = std::atan2(r.z(), r.x()) + M_PI;  // [0, 2 pi]
    const int s = std::min(sectors - 1, static_cast<int>(angle / (2 * M_PI / sectors)));
    muscles[s].elements.push_back(e);
    muscles[s].fibers.push_back(Vec3(-r.z(), 0.0, r.x()).normalized());
  }
  for (Muscle& m : muscles) m.stiffness = 2e5;
  return muscles;
}

std::vector<int> NodesWhere(const Mesh& mesh, const std::function<bool(const Vec3&)>& keep) {
  std::vector<int> nodes;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (keep(mesh.vertices.col(i))) nodes.push_back(i);
  return nodes;
}

}  // namespace

std::string Locomotion::name() const {
  switch (body_) {
    case Body::kTorus:
      return "torus";
    case Body::kQuadruped:
      return "quadruped";
    case Body::kCow:
      return "cow";
  }
  return "";
}

std::string Locomotion::description() const {
  const std::string what = body_ == Body::kTorus       ? "a soft torus (wheel) rolling"
                           : body_ == Body::kQuadruped ? "a box-legged quadruped walking"
                                                       : "the Spot cow walking";
  return "open-loop locomotion with frictional contact: " + what +
         " forward by periodic muscle activations, bounded, without tipping over (Ipopt)";
}

Scene Locomotion::MakeScene(InstanceSize size) const {
  const bool small = size == InstanceSize::kSmall;
  Scene scene;
  switch (body_) {
    case Body::kTorus: {
      const SurfaceMesh surface = ReadObj(SharedDataPath("meshes/torus.obj"));
      const double extent = (surface.vertices.rowwise().maxCoeff() - surface.vertices.rowwise().minCoeff()).maxCoeff();
      scene.mesh = VoxelizeSurface(surface, small ? 0.016 : 0.0125, 0.1 / extent);
      PlaceOnGround(&scene.mesh);
      scene.muscles = RingMuscles(scene.mesh, small ? 4 : 8);
      break;
    }
    case Body::kQuadruped:
      scene.mesh = QuadrupedMesh(small ? 0.03 : 0.015);
      scene.muscles = LegMuscles(scene.mesh, 0.03, /*split=*/!small);
      break;
    case Body::kCow: {
      const SurfaceMesh surface = ReadObj(SharedDataPath("meshes/spot.obj"));
      const double length = surface.vertices.row(0).maxCoeff() - surface.vertices.row(0).minCoeff();
      scene.mesh = VoxelizeSurface(surface, small ? 0.02 : 0.0125, 0.1 / length);
      PlaceOnGround(&scene.mesh);
      const double height = scene.mesh.vertices.row(2).maxCoeff();
      scene.muscles = LegMuscles(scene.mesh, 0.35 * height, /*split=*/false);
      break;
    }
  }
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

SolverOptions Locomotion::BaseOptions(InstanceSize size) const {
  SolverOptions o = TrajectoryOptimizationProblem::BaseOptions(size);
  // PD needs ~1000 iterations per step to reach 1e-6 on these muscle-driven
  // bodies in contact; the small instance stops at 1e-4 (forward travel
  // changes by ~3e-4 cm) so that it runs in about a minute with both methods.
  o.rel_tolerance = size == InstanceSize::kSmall ? 1e-4 : 1e-6;
  return o;
}

Ipopt::SmartPtr<solvers::RolloutNlp> Locomotion::MakeNlp(const SolverOptions& options, InstanceSize size) const {
  using namespace solvers;
  const int K = steps(size);
  const double h = time_step(size);
  Ipopt::SmartPtr<RolloutNlp> nlp = new RolloutNlp(std::make_unique<RolloutFunction>(MakeScene(size), options, K));
  const Scene& scene = nlp->function().scene();
  const Mesh& mesh = scene.mesh;
  const State& initial = nlp->function().base().initial;

  const int muscles = static_cast<int>(scene.muscles.size());
  std::vector<ActivationBlock::Channel> channels;
  for (int m = 0; m < muscles; ++m) channels.push_back({m, std::make_unique<FourierSignal>(K, h, kPeriod, 1)});
  auto activation = std::make_unique<ActivationBlock>(std::move(channels));
  VectorXd start(3 * muscles);
  for (int m = 0; m < muscles; ++m) {
    const double phase = 2 * M_PI * m / muscles;  // a travelling wave over the muscles
    start.segment<3>(3 * m) << 1.0, 0.1 * std::cos(phase), 0.1 * std::sin(phase);
    activation->SetBounds(3 * m, 1, kMinActivation, kMaxActivation);
    activation->SetBounds(3 * m + 1, 2, -(kMaxActivation - kMinActivation) / 2, (kMaxActivation - kMinActivation) / 2);
  }
  activation->SetInitial(start);
  const FourierSignal signal(K, h, kPeriod, 1);
  const int offset = nlp->AddVariables(std::move(activation));
  for (int m = 0; m < muscles; ++m)
    for (LinearConstraint& row : SignalRangeConstraints(signal, offset + 3 * m, kMinActivation, kMaxActivation,
                                                        "activation_range_" + std::to_string(m)))
      nlp->AddLinearConstraint(std::move(row));

  const TrackedPoint com = CentreOfMass(nlp->function().simulator().LumpedMass());
  nlp->AddObjective(std::make_unique<PointTravel>(com, 0, kFinalState, Vec3::UnitX(), "forward_travel"), -100.0);

  // The "up" axis: the wheel's axle for the torus, lower to upper body otherwise.
  const Vec3 lo = mesh.vertices.rowwise().minCoeff(), hi = mesh.vertices.rowwise().maxCoeff();
  const double tol = 1e-9;
  std::vector<int> a, b;
  if (body_ == Body::kTorus) {
    a = NodesWhere(mesh, [&](const Vec3& p) { return p.y() <= lo.y() + tol; });
    b = NodesWhere(mesh, [&](const Vec3& p) { return p.y() >= hi.y() - tol; });
  } else {
    const double height = hi.z() - lo.z();
    a = NodesWhere(mesh, [&](const Vec3& p) { return p.z() < lo.z() + 0.5 * height; });
    b = NodesWhere(mesh, [&](const Vec3& p) { return p.z() > lo.z() + 0.75 * height; });
  }
  const TrackedPoint pa = MeanOf(mesh.num_vertices(), a), pb = MeanOf(mesh.num_vertices(), b);
  const Vec3 rest_axis = (pb.At(initial.x) - pa.At(initial.x)).normalized();
  nlp->AddConstraint(std::make_unique<AxisAlignment>(pa, pb, kFinalState, rest_axis, "upright"),
                     std::cos(kMaxTiltDegrees * M_PI / 180), 1.0);
  return nlp;
}

solvers::IpoptOptions Locomotion::DefaultIpoptOptions(InstanceSize size) const {
  solvers::IpoptOptions o;
  o.int_options = {
      {"max_iter", size == InstanceSize::kSmall ? 8 : 40}, {"acceptable_iter", 5}, {"accept_after_max_steps", 3}};
  o.num_options = {{"tol", 1e-4}, {"acceptable_tol", 1e-3}};
  return o;
}

}  // namespace diffpd::problems
