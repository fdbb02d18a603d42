// Steps a small clamped beam with the installed library and checks that it
// sags under gravity; differentiates the tip's height w.r.t. Young's modulus
// with the rollout core (a stiffer beam sags less), and, when built with the
// adapters, evaluates the same row through a Ceres cost function and an
// Ipopt TNLP. Exits non-zero if a check fails.
#include <cstdio>
#include <memory>

#include <diffpd/box_mesh.h>
#include <diffpd/simulator.h>
#include <diffpd/solvers/core/material_block.h>
#include <diffpd/solvers/core/rollout_function.h>
#include <diffpd/solvers/core/trajectory_function.h>
#ifdef CONSUMER_WITH_CERES
#include <diffpd/solvers/ceres/rollout_cost_function.h>
#endif
#ifdef CONSUMER_WITH_IPOPT
#include <diffpd/solvers/ipopt/rollout_nlp.h>
#endif

int main() {
  using namespace diffpd;
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(4, 1, 1), Vec3(0.2, 0.05, 0.05));
  scene.gravity = Vec3(0, 0, -9.81);
  std::vector<int> clamped;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(0, i) == 0.0) clamped.push_back(i);
  FixNodes(&scene, clamped);
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.rel_tolerance = 1e-4;
  Simulator sim(scene, options);
  State s = sim.RestState();
  for (int k = 0; k < 5; ++k) s = sim.Step(s, StepInput());
  const int tip = scene.mesh.num_vertices() - 1;
  const double tip_z = s.x(3 * tip + 2) - scene.mesh.vertices(2, tip);
  std::printf("consumer: tip moved %.3e m along z\n", tip_z);
  if (!(tip_z < 0)) return 1;

  auto function = std::make_unique<solvers::RolloutFunction>(scene, options, 5);
  function->AddBlock(std::make_unique<solvers::MaterialBlock>(
      std::vector<solvers::MaterialBlock::Entry>{solvers::MaterialField::kYoungsModulus}, scene));
  function->AddFunctional(std::make_unique<solvers::PointCoordinate>(solvers::NodePoint(scene.mesh.num_vertices(), tip),
                                                                     solvers::kFinalState, Vec3::UnitZ()));
  VectorXd value;
  MatrixXd jacobian;
  if (!function->Evaluate(function->initial_parameters(), {0}, &value, &jacobian)) return 2;
  std::printf("consumer: d tip z / d E = %.3e m/Pa\n", jacobian(0, 0));
  if (!(jacobian(0, 0) > 0)) return 3;
#ifdef CONSUMER_WITH_CERES
  const solvers::RolloutCostFunction cost(function.get(), {0});
  double e = scene.material.youngs_modulus, residual = 0, d_residual = 0;
  const double* parameters[1] = {&e};
  double* jacobians[1] = {&d_residual};
  if (!cost.Evaluate(parameters, &residual, jacobians) || residual != value(0) || d_residual != jacobian(0, 0))
    return 4;
  std::printf("consumer: the Ceres cost function agrees\n");
#endif
#ifdef CONSUMER_WITH_IPOPT
  Ipopt::SmartPtr<solvers::RolloutNlp> nlp = new solvers::RolloutNlp(std::move(function));
  nlp->AddConstraintRows({0}, -1.0, 1.0);
  Ipopt::Index n = 0, m = 0, nnz = 0, nnz_h = 0;
  Ipopt::TNLP::IndexStyleEnum style;
  if (!nlp->get_nlp_info(n, m, nnz, nnz_h, style) || n != 1 || m != 1 || nnz != 1) return 5;
  std::printf("consumer: the Ipopt TNLP has %d variable and %d constraint\n", static_cast<int>(n), static_cast<int>(m));
#endif
  return 0;
}
