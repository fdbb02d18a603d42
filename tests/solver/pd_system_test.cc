// The PD matrix A is factorised once per (mesh, h, weights, Dirichlet set):
// counted across iterations, steps and rollouts; one scalar factor serves
// the axes whose Dirichlet sets agree; solves match a dense reference.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "diffpd/simulator.h"
#include "fem/fem_model.h"
#include "solver/pd_system.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

TEST(PdSystemTest, FactorisesOncePerTimeStepAndMaterialAcrossStepsAndRollouts) {
  const Scene scene = testing::SmallBeamScene();
  SolverOptions o;
  o.method = Method::kPd;
  Simulator sim(scene, o);
  EXPECT_EQ(sim.num_pd_factorizations(), 0);
  const Rollout r = sim.Simulate(sim.RestState(), std::vector<StepInput>(5));
  EXPECT_GT(r.reports[0].iterations, 1);
  EXPECT_EQ(sim.num_pd_factorizations(), 1);
  LossGradient dl(5);
  dl.dx[5] = VectorXd::Ones(sim.num_dofs());
  sim.Backward(r, dl);
  sim.Simulate(sim.RestState(), std::vector<StepInput>(5));
  EXPECT_EQ(sim.num_pd_factorizations(), 1);
  SolverOptions same_h = o;
  same_h.rel_tolerance = 1e-3;  // not a reason to refactorise
  sim.SetOptions(same_h);
  sim.Step(sim.RestState(), StepInput());
  EXPECT_EQ(sim.num_pd_factorizations(), 1);
  SolverOptions new_h = o;
  new_h.time_step = 0.005;
  sim.SetOptions(new_h);
  sim.Step(sim.RestState(), StepInput());
  EXPECT_EQ(sim.num_pd_factorizations(), 2);
  MaterialParameters m = scene.material;
  m.youngs_modulus *= 2;
  sim.SetMaterial(m);
  sim.Step(sim.RestState(), StepInput());
  EXPECT_EQ(sim.num_pd_factorizations(), 3);
  sim.Step(sim.RestState(), StepInput());
  EXPECT_EQ(sim.num_pd_factorizations(), 3);
}

TEST(PdSystemTest, AxesWithTheSameDirichletSetShareOneFactorAndSolvesMatchDense) {
  Scene scene = testing::SmallBeamScene();
  internal::FemModel fem(scene.mesh);
  const int n = scene.mesh.num_dofs();
  std::vector<char> fixed(n, 0);
  for (const int d : scene.dirichlet.dofs) fixed[d] = 1;
  internal::PdSystem same(fem, fixed);
  EXPECT_EQ(same.num_groups(), 1);
  // Free x at the clamp (as for the starfish): two groups.
  std::vector<char> mixed = fixed;
  for (int i = 0; i < n / 3; ++i) mixed[3 * i] = 0;
  internal::PdSystem two(fem, mixed);
  EXPECT_EQ(two.num_groups(), 2);
  two.Update(0.01, 1e3, 5e5);
  // Dense reference: A over free DoFs.
  Eigen::MatrixXd a(n, n);
  for (int c = 0; c < n; ++c) {
    VectorXd e = VectorXd::Zero(n);
    e(c) = 1;
    a.col(c) = two.Apply(e);
  }
  VectorXd r = VectorXd::LinSpaced(n, -1, 2);
  const VectorXd z = two.Solve(r);
  for (int d = 0; d < n; ++d)
    if (mixed[d]) r(d) = 0;
  EXPECT_LT((a * z - r).norm() / r.norm(), 1e-12);
  for (int d = 0; d < n; ++d)
    if (mixed[d]) EXPECT_EQ(z(d), 0.0);
}

}  // namespace
}  // namespace diffpd
