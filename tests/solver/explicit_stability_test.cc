// Simulator::ExplicitStableTimeStep: semi-implicit Euler's stability limit
// 2 / omega_max, checked against a dense eigen-decomposition of M^-1 K built
// from the energy alone, and against what semi-implicit Euler does on either
// side of it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

SolverOptions SemiImplicit(double time_step) {
  SolverOptions options;
  options.method = Method::kSemiImplicit;
  options.time_step = time_step;
  options.num_threads = 1;
  return options;
}

// 2 / sqrt(largest eigenvalue of M^-1 K) over the free DoFs, K the Hessian of
// the elastic energy at x by central second differences of the energy
// (exact up to its quartic terms near the rest shape, where the energy and
// its gradient vanish).
double DenseStableTimeStep(Simulator* sim, const VectorXd& x, double delta) {
  const Scene& scene = sim->scene();
  std::vector<char> fixed(x.size(), 0);
  for (int d : scene.dirichlet.dofs) fixed[d] = 1;
  std::vector<int> free;
  for (int d = 0; d < x.size(); ++d)
    if (!fixed[d]) free.push_back(d);
  const int m = static_cast<int>(free.size());
  const VectorXd mass = sim->LumpedMass();
  auto energy = [&](int i, double si, int j, double sj) {
    VectorXd y = x;
    y(i) += si * delta;
    y(j) += sj * delta;
    return sim->ElasticEnergy(y);
  };
  MatrixXd s(m, m);
  for (int a = 0; a < m; ++a)
    for (int b = a; b < m; ++b) {
      const int i = free[a], j = free[b];
      const double k =
          (energy(i, 1, j, 1) - energy(i, 1, j, -1) - energy(i, -1, j, 1) + energy(i, -1, j, -1)) / (4 * delta * delta);
      s(a, b) = s(b, a) = k / std::sqrt(mass(i) * mass(j));
    }
  const double largest = Eigen::SelfAdjointEigenSolver<MatrixXd>(s, Eigen::EigenvaluesOnly).eigenvalues()(m - 1);
  return 2 / std::sqrt(largest);
}

TEST(ExplicitStableTimeStepTest, IsTwoOverTheHighestNaturalFrequencyOfTheDenseStiffness) {
  for (bool tets : {false, true}) {
    SCOPED_TRACE(tets ? "tetrahedra" : "hexahedra");
    Simulator sim(testing::SmallBeamScene(tets), SemiImplicit(1e-4));
    const VectorXd rest = sim.RestState().x;
    const double dense = DenseStableTimeStep(&sim, rest, 1e-6);
    const double lanczos = sim.ExplicitStableTimeStep(rest);
    EXPECT_NEAR(lanczos / dense, 1, 1e-5) << "Lanczos " << lanczos << " s, dense " << dense << " s";
    // A Ritz value is at most the eigenvalue: the estimate never undercuts the limit by more than rounding.
    EXPECT_GE(lanczos, dense * (1 - 1e-7));
  }
}

// Symplectic Euler on a linear oscillator of frequency omega is stable for
// h omega < 2 and grows by |lambda| > 1.6 per step at h omega = 2.06: from a
// tiny random velocity (1e-6 m/s) the beam (0.16 m long) stays within 1e-6 m
// of rest for 3000 steps at 0.97 x the limit, moves by more than 5 cm within
// 100 steps at 1.03 x (after which its nonlinearity slows the growth), and
// at 1.5 x tears apart with the limit in the message.
TEST(ExplicitStableTimeStepTest, SemiImplicitEulerIsStableJustBelowItAndDivergesJustAbove) {
  Scene scene = testing::SmallBeamScene();
  scene.gravity = Vec3::Zero();
  double limit = 0;
  State start;
  {
    Simulator sim(scene, SemiImplicit(1e-4));
    start = sim.RestState();
    limit = sim.ExplicitStableTimeStep(start.x);
  }
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1e-6);
  for (Eigen::Index d = 0; d < start.v.size(); ++d) start.v(d) = normal(rng);
  for (int d : scene.dirichlet.dofs) start.v(d) = 0;
  auto largest_displacement = [&](double factor, int steps) {
    Simulator sim(scene, SemiImplicit(factor * limit));
    const Rollout r = sim.Simulate(start, std::vector<StepInput>(steps));
    double largest = 0;
    for (const State& s : r.states) largest = std::max(largest, (s.x - start.x).cwiseAbs().maxCoeff());
    return largest;
  };
  EXPECT_LT(largest_displacement(0.97, 3000), 1e-6) << "limit " << limit << " s";
  EXPECT_GT(largest_displacement(1.03, 100), 0.05) << "limit " << limit << " s";

  Simulator torn(scene, SemiImplicit(1.5 * limit));
  try {
    torn.Simulate(start, std::vector<StepInput>(100));
    ADD_FAILURE() << "no divergence at 1.5 x the limit " << limit << " s";
  } catch (const SolverError& e) {
    EXPECT_NE(std::string(e.what()).find("above semi-implicit Euler's stability limit at the rest shape, about "),
              std::string::npos)
        << e.what();
  }
}

TEST(ExplicitStableTimeStepTest, RejectsPositionsAndActivationsOfTheWrongShape) {
  Simulator sim(testing::SmallBeamScene(), SemiImplicit(1e-4));
  EXPECT_THROW_MESSAGE(sim.ExplicitStableTimeStep(VectorXd::Zero(5)), InvalidInputError,
                       "ExplicitStableTimeStep: x has 5 entries, expected 135 (3 x number of nodes)");
  VectorXd x = sim.RestState().x;
  x(4) = std::nan("");
  EXPECT_THROW_MESSAGE(sim.ExplicitStableTimeStep(x), InvalidInputError,
                       "ExplicitStableTimeStep: x has a non-finite entry");
  EXPECT_THROW_MESSAGE(sim.ExplicitStableTimeStep(sim.RestState().x, VectorXd::Ones(2)), InvalidInputError,
                       "ExplicitStableTimeStep: activation has 2 entries, expected 0 (one per muscle)");
}

TEST(ExplicitStableTimeStepTest, IsInfiniteWhenEveryDofIsFixed) {
  Scene scene = testing::SmallBeamScene();
  FixNodes(&scene, [&] {
    std::vector<int> all(scene.mesh.num_vertices());
    for (int i = 0; i < scene.mesh.num_vertices(); ++i) all[i] = i;
    return all;
  }());
  Simulator sim(scene, SemiImplicit(1e-4));
  EXPECT_TRUE(std::isinf(sim.ExplicitStableTimeStep(sim.RestState().x)));
}

}  // namespace
}  // namespace diffpd
