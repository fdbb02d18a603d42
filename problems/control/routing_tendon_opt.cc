#include "control/routing_tendon_opt.h"

#include "diffpd/box_mesh.h"
#include "diffpd/solvers/core/activation_block.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "scenes/routing_tendon.h"

namespace diffpd::problems {
namespace {

// The node at the centre of the top face (or the closest one).
int TipNode(const Mesh& mesh) {
  const Vec3 hi = mesh.vertices.rowwise().maxCoeff();
  const Vec3 lo = mesh.vertices.rowwise().minCoeff();
  const Vec3 top((lo.x() + hi.x()) / 2, (lo.y() + hi.y()) / 2, hi.z());
  int best = 0;
  for (int i = 1; i < mesh.num_vertices(); ++i)
    if ((mesh.vertices.col(i) - top).norm() < (mesh.vertices.col(best) - top).norm()) best = i;
  return best;
}

// RoutingTendon's column and muscle layout with 2 x 2 x 6 cells.
Scene SmallColumn() {
  Scene scene = RoutingTendon().MakeScene();
  const Eigen::Vector3i cells(2, 2, 6);
  const Vec3 size = scene.mesh.vertices.rowwise().maxCoeff() - scene.mesh.vertices.rowwise().minCoeff();
  scene.mesh = MakeBoxHexMesh(cells, size);
  scene.dirichlet = DirichletBoundary();
  std::vector<int> base;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) <= 1e-9) base.push_back(i);
  FixNodes(&scene, base);
  for (Muscle& m : scene.muscles) m.elements.clear();
  // Element (i ny + j) nz + k is cell (i, j, k) (box_mesh.h).
  for (int i = 0; i < cells.x(); ++i)
    for (int j = 0; j < cells.y(); ++j)
      for (int k = 0; k < cells.z(); ++k) {
        const int e = (i * cells.y() + j) * cells.z() + k;
        if (i == cells.x() - 1) scene.muscles[0].elements.push_back(e);
        if (i == 0) scene.muscles[1].elements.push_back(e);
        if (j == cells.y() - 1) scene.muscles[2].elements.push_back(e);
        if (j == 0) scene.muscles[3].elements.push_back(e);
      }
  return scene;
}

}  // namespace

std::string RoutingTendonOpt::description() const {
  return "soft column with four tendons: bounded activations over time bring the tip marker to a target (Ipopt)";
}

Scene RoutingTendonOpt::MakeScene(InstanceSize size) const {
  return size == InstanceSize::kSmall ? SmallColumn() : RoutingTendon().MakeScene();
}

int RoutingTendonOpt::default_steps() const { return RoutingTendon().default_steps(); }

std::vector<StepInput> RoutingTendonOpt::Inputs(const Simulator& sim, int steps) const {
  return RoutingTendon().Inputs(sim, steps);
}

Ipopt::SmartPtr<solvers::RolloutNlp> RoutingTendonOpt::MakeNlp(const SolverOptions& options, InstanceSize size) const {
  using namespace solvers;
  const int K = steps(size);
  const int knots = size == InstanceSize::kSmall ? 4 : 6;
  Ipopt::SmartPtr<RolloutNlp> nlp = new RolloutNlp(std::make_unique<RolloutFunction>(MakeScene(size), options, K));
  const Scene& scene = nlp->function().scene();
  std::vector<ActivationBlock::Channel> channels;
  for (int m = 0; m < static_cast<int>(scene.muscles.size()); ++m)
    channels.push_back({m, std::make_unique<PiecewiseLinearSignal>(K, knots)});
  auto activation = std::make_unique<ActivationBlock>(std::move(channels));
  activation->SetBounds(0.6, 1.0);
  const int count = activation->size();
  const int offset = nlp->AddVariables(std::move(activation));
  nlp->AddRegularization(offset, count, 1e-2, 1.0);

  const Mesh& mesh = scene.mesh;
  const TrackedPoint tip = NodePoint(mesh.num_vertices(), TipNode(mesh));
  const Vec3 rest = tip.At(nlp->function().base().initial.x);
  const Vec3 target = rest + Vec3(0.02, 0.012, -0.004);
  nlp->AddObjective(std::make_unique<PointDistanceSquared>(tip, kFinalState, target, "tip_error"), 1e6);
  for (int k : {K / 2, K})
    nlp->AddConstraint(std::make_unique<PointCoordinate>(tip, k, Vec3::UnitZ(), "tip_height_" + std::to_string(k)),
                       rest.z() - 0.01, 1e20);
  return nlp;
}

solvers::IpoptOptions RoutingTendonOpt::DefaultIpoptOptions(InstanceSize size) const {
  solvers::IpoptOptions o;
  o.int_options = {{"max_iter", size == InstanceSize::kSmall ? 25 : 60}, {"acceptable_iter", 5}};
  o.num_options = {{"tol", 1e-4}, {"acceptable_tol", 1e-3}};
  return o;
}

}  // namespace diffpd::problems
