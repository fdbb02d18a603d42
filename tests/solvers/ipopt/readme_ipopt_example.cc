// Finds how to throw a soft cube so that it lands 20 cm ahead after passing
// 10 cm above its start at mid-flight: the README's Ipopt example program
// (compiled and run by readme_ipopt_example_test). Usage: readme_ipopt_example
#include <cstdio>
#include <numeric>

#include "diffpd/box_mesh.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "diffpd/solvers/ipopt/ipopt_solve.h"

int main() {
  using namespace diffpd;
  using namespace diffpd::solvers;
  // A free soft cube (10 cm, 2 x 2 x 2 hexahedra) under gravity, 0.2 s in steps of 10 ms.
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(2, 2, 2), Vec3(0.1, 0.1, 0.1));
  scene.material = MaterialParameters{1e5, 0.4, 1e3};
  scene.gravity = Vec3(0, 0, -9.81);
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  const int steps = 20;
  Ipopt::SmartPtr<RolloutNlp> nlp = new RolloutNlp(std::make_unique<RolloutFunction>(scene, options, steps));

  // The variables: one initial velocity shared by every node (m/s), each axis in [-3, 3].
  std::vector<int> nodes(scene.mesh.num_vertices());
  std::iota(nodes.begin(), nodes.end(), 0);
  auto velocity = std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, nodes);
  velocity->SetBounds(-3.0, 3.0);
  nlp->AddVariables(std::move(velocity));
  // The objective: the centre of mass's horizontal distance (squared) to a
  // point 20 cm ahead at the end; the constraint: 10 cm up at mid-flight.
  const TrackedPoint com = CentreOfMass(nlp->function().simulator().LumpedMass());
  const Vec3 start = com.At(nlp->function().base().initial.x);
  nlp->AddObjective(
      std::make_unique<PointDistanceSquared>(com, kFinalState, start + Vec3(0.2, 0, 0), "miss", Vec3(1, 1, 0)));
  nlp->AddConstraint(std::make_unique<PointCoordinate>(com, steps / 2, Vec3::UnitZ(), "apex"), start.z() + 0.1, 1e20);

  IpoptOptions ipopt;  // exact gradients and Jacobians; limited-memory Hessian
  ipopt.num_options = {{"tol", 1e-8}};
  const IpoptSummary summary = SolveWithIpopt(nlp, ipopt);
  std::printf("%s\nv0 = (%.4f, %.4f, %.4f) m/s\n", summary.BriefReport().c_str(), summary.x(0), summary.x(1),
              summary.x(2));
  return summary.succeeded() ? 0 : 1;
}
