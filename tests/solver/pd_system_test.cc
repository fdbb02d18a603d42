// The PD matrix A is factorised once per (mesh, h, weights, Dirichlet set):
// counted across iterations, steps and rollouts; one scalar factor serves
// the axes whose Dirichlet sets agree; solves match a dense reference; solves
// on 2 threads (the factor's copy split over elimination subtrees) agree
// with 1 thread's to rounding, with one and with two factor groups.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <random>

#include "diffpd/box_mesh.h"
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
  EXPECT_EQ(sim.pd_factorization_seconds(), 0.0);
  const Rollout r = sim.Simulate(sim.RestState(), std::vector<StepInput>(5));
  EXPECT_GT(r.reports[0].iterations, 1);
  EXPECT_EQ(sim.num_pd_factorizations(), 1);
  const double factor_seconds = sim.pd_factorization_seconds();
  EXPECT_GT(factor_seconds, 0.0);
  LossGradient dl(5);
  dl.dx[5] = VectorXd::Ones(sim.num_dofs());
  sim.Backward(r, dl);
  sim.Simulate(sim.RestState(), std::vector<StepInput>(5));
  EXPECT_EQ(sim.num_pd_factorizations(), 1);
  EXPECT_EQ(sim.pd_factorization_seconds(), factor_seconds);  // reused: no time added
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

TEST(PdSystemTest, WithMaterialRegionsFactorisesOncePerTimeStepAndMaterials) {
  const Scene scene = testing::TwoRegionBeamScene();
  for (Method method : {Method::kPd, Method::kPdLbfgs}) {
    SolverOptions o;
    o.method = method;
    o.max_iterations = 5000;  // PD needs ~800 iterations per step here
    Simulator sim(scene, o);
    const Rollout r = sim.Simulate(sim.RestState(), std::vector<StepInput>(4));
    EXPECT_EQ(sim.num_pd_factorizations(), 1);
    LossGradient dl(4);
    dl.dx[4] = VectorXd::Ones(sim.num_dofs());
    sim.Backward(r, dl);
    sim.Tangents(r, {InputDirection::RegionYoungsModulus(1, 2)});
    EXPECT_EQ(sim.num_pd_factorizations(), 1);
    sim.SetRegionMaterial(0, scene.material_regions[0].material);  // unchanged values
    sim.SetMaterial(scene.material);
    sim.Step(sim.RestState(), StepInput());
    EXPECT_EQ(sim.num_pd_factorizations(), 1);
    MaterialParameters m = scene.material_regions[1].material;
    m.youngs_modulus *= 2;
    sim.SetRegionMaterial(1, m);
    sim.Step(sim.RestState(), StepInput());
    EXPECT_EQ(sim.num_pd_factorizations(), 2);
    m.density *= 2;  // a density alone changes A too
    sim.SetRegionMaterial(1, m);
    sim.Step(sim.RestState(), StepInput());
    sim.Step(sim.RestState(), StepInput());
    EXPECT_EQ(sim.num_pd_factorizations(), 3);
  }
}

TEST(PdSystemTest, PartsWeightTheirOwnElementsAndMasses) {
  const Scene scene = testing::TwoRegionBeamScene();
  internal::FemModel fem(scene.mesh);
  const int nodes = fem.num_nodes();
  const std::vector<char> free_dofs(3 * nodes, 0);
  std::vector<int> part(fem.num_elements(), 0);
  for (size_t r = 0; r < scene.material_regions.size(); ++r)
    for (const int e : scene.material_regions[r].elements) part[e] = static_cast<int>(r) + 1;
  const double h = 0.01;
  internal::PdSystem one(fem, free_dofs), equal(fem, free_dofs, part, 3), mixed(fem, free_dofs, part, 3);
  one.Update(h, 1e3, 5e5);
  equal.Update(h, {1e3, 1e3, 1e3}, {5e5, 5e5, 5e5});
  const std::vector<double> rho = {1e3, 2e3, 0.5e3}, w = {5e5, 1e5, 2e6};
  mixed.Update(h, rho, w);
  // Dense reference: A_s = sum_p (rho_p / h^2) diag(m_p) + sum_e w_p(e) L_e.
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(nodes, nodes);
  const int k = fem.nodes_per_element();
  for (int e = 0; e < fem.num_elements(); ++e)
    for (int q = 0; q < fem.samples_per_element(); ++q) {
      const int s = e * fem.samples_per_element() + q;
      const Eigen::Map<const Eigen::MatrixXd> g(fem.grad(s), k, 3);
      const Eigen::MatrixXd le = w[part[e]] * fem.sample_volume(s) * g * g.transpose();
      for (int i = 0; i < k; ++i)
        for (int j = 0; j < k; ++j) a(scene.mesh.elements(i, e), scene.mesh.elements(j, e)) += le(i, j);
    }
  for (int p = 0; p < 3; ++p) a.diagonal() += (rho[p] / (h * h)) * fem.UnitLumpedMass(part, p);
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  VectorXd x(3 * nodes);
  for (int i = 0; i < x.size(); ++i) x(i) = u(rng);
  EXPECT_EQ((one.Apply(x) - equal.Apply(x)).norm(), 0.0);
  const Eigen::Map<const Eigen::MatrixXd> xm(x.data(), 3, nodes);
  const Eigen::MatrixXd expected = xm * a;  // A_s symmetric: (A_s x_axis) per row
  const VectorXd y = mixed.Apply(x);
  EXPECT_LT((y - Eigen::Map<const VectorXd>(expected.data(), x.size())).norm(), 1e-12 * y.norm());
  EXPECT_LT((mixed.Apply(mixed.Solve(x)) - x).norm(), 1e-10 * x.norm());
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
  for (int d = 0; d < n; ++d) {
    if (mixed[d]) {
      EXPECT_EQ(z(d), 0.0);
    }
  }
}

TEST(PdSystemTest, SolvesOnTwoThreadsAgreeWithOneThread) {
  // The cantilever's grid (33 x 9 x 9 nodes): a factor large enough to be
  // split (smaller ones are solved serially), clamped at x = 0.
  const Mesh mesh = MakeBoxHexMesh(Eigen::Vector3i(32, 8, 8), Vec3(0.32, 0.08, 0.08));
  internal::FemModel fem(mesh);
  const int n = mesh.num_dofs();
  std::vector<char> fixed(n, 0), mixed(n, 0);  // mixed: x stays free at the clamp (two groups)
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.vertices(0, i) < 1e-9)
      for (int d = 0; d < 3; ++d) {
        fixed[3 * i + d] = 1;
        mixed[3 * i + d] = d > 0;
      }
  std::mt19937 rng(3);
  std::normal_distribution<double> normal;
  const MatrixXd r = MatrixXd::NullaryExpr(n, 2, [&]() { return normal(rng); });
  for (const std::vector<char>* dirichlet : {&fixed, &mixed}) {
    internal::PdSystem serial(fem, *dirichlet), parallel(fem, *dirichlet);
    EXPECT_EQ(serial.num_groups(), dirichlet == &fixed ? 1 : 2);
    parallel.SetSolveThreads(2);
    serial.Update(0.01, 1e3, 3e5);
    parallel.Update(0.01, 1e3, 3e5);
    const MatrixXd expected = serial.Solve(r), got = parallel.Solve(r);
    EXPECT_LT((got - expected).norm(), 1e-13 * expected.norm());
    VectorXd rhs = r.col(1);
    for (int d = 0; d < n; ++d)
      if ((*dirichlet)[d]) rhs(d) = 0;
    EXPECT_LT((parallel.Apply(parallel.Solve(rhs)) - rhs).norm(), 1e-12 * rhs.norm());
  }
}

}  // namespace
}  // namespace diffpd
