// The adjoint's tolerance follows the accuracy the forward reached
// (SolverOptions::backward_rel_tolerance = 0): the rule itself, and that the
// gradient it gives is as accurate as an exact (direct) adjoint's at the same
// forward, with fewer iterations than a fixed tight tolerance.
#include "solver/adjoint_tolerance.h"

#include <gtest/gtest.h>

#include <random>

#include "diffpd/simulator.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

StepReport Reached(double initial, double final_residual) {
  StepReport r;
  r.initial_residual = initial;
  r.final_residual = final_residual;
  return r;
}

TEST(AdjointToleranceTest, DerivedFromTheRelativeResidualTheForwardReached) {
  SolverOptions o;
  o.backward_rel_tolerance = 0;
  o.backward_tolerance_factor = 0.01;
  const StepReport step = Reached(2.0, 1e-4);  // reached 5e-5
  EXPECT_DOUBLE_EQ(internal::AdjointRelTolerance(o, 1e-4, &step), 0.01 * 5e-5);
  // Never looser than the factor times the forward's own tolerance (a step
  // that stopped on abs_tolerance or at the rounding floor).
  const StepReport loose = Reached(2.0, 1.0);
  EXPECT_DOUBLE_EQ(internal::AdjointRelTolerance(o, 1e-4, &loose), 0.01 * 1e-4);
  // No report, or a step that started at its solution: the forward's tolerance.
  EXPECT_DOUBLE_EQ(internal::AdjointRelTolerance(o, 1e-4, nullptr), 0.01 * 1e-4);
  const StepReport at_rest = Reached(0.0, 0.0);
  EXPECT_DOUBLE_EQ(internal::AdjointRelTolerance(o, 1e-4, &at_rest), 0.01 * 1e-4);
  // Not below what CG can reach in double precision.
  const StepReport exact = Reached(1.0, 1e-16);
  EXPECT_DOUBLE_EQ(internal::AdjointRelTolerance(o, 1e-4, &exact), internal::kMinAdjointRelTolerance);
  // Forward with rel_tolerance 0 (absolute only): the reached ratio alone.
  EXPECT_DOUBLE_EQ(internal::AdjointRelTolerance(o, 0.0, &step), 0.01 * 5e-5);
  // A fixed tolerance is used as given.
  o.backward_rel_tolerance = 3e-7;
  EXPECT_DOUBLE_EQ(internal::AdjointRelTolerance(o, 1e-4, &step), 3e-7);
}

// The small clamped beam, deformed and moving, 8 steps of PD-LBFGS at
// forward rtol 1e-6; the loss is random linear in the final state.
struct AdjointRun {
  VectorXd gradient;
  int iterations = 0;
};

AdjointRun Gradient(const SolverOptions& options, const State& start, int steps) {
  Simulator sim(testing::SmallBeamScene(), options);
  const Rollout r = sim.Simulate(start, std::vector<StepInput>(steps));
  std::mt19937_64 rng(5);
  LossGradient dl(steps);
  dl.dx[steps] = testing::RandomVector(sim.num_dofs(), &rng, 1.0);
  dl.dv[steps] = testing::RandomVector(sim.num_dofs(), &rng, 1.0);
  const RolloutGradient g = sim.Backward(r, dl);
  AdjointRun out;
  out.gradient.resize(2 * g.x0.size() + 3);
  out.gradient << g.x0, g.v0, g.youngs_modulus, g.poissons_ratio, g.density;
  out.iterations = g.report.linear_iterations;
  return out;
}

TEST(AdjointToleranceTest, DerivedToleranceGradientIsAsAccurateAsAnExactAdjointWithFewerIterations) {
  const int steps = 8;
  SolverOptions reference = testing::TightOptions(Method::kNewtonCholesky);
  const State start = testing::MovingStart(Simulator(testing::SmallBeamScene(), reference));
  const VectorXd exact = Gradient(reference, start, steps).gradient;
  SolverOptions pd;
  pd.method = Method::kPdLbfgs;
  pd.rel_tolerance = 1e-6;
  pd.num_threads = 1;
  pd.adjoint_solver = AdjointSolver::kIterative;
  const AdjointRun derived = Gradient(pd, start, steps);  // backward_rel_tolerance = 0
  SolverOptions tight = pd;
  tight.backward_rel_tolerance = 1e-12;
  const AdjointRun fixed = Gradient(tight, start, steps);
  SolverOptions loose = pd;
  loose.backward_rel_tolerance = 1e-4;  // 100x the forward's: too loose
  const AdjointRun coarse = Gradient(loose, start, steps);
  SolverOptions direct = pd;
  direct.adjoint_solver = AdjointSolver::kDirect;
  const double floor = (Gradient(direct, start, steps).gradient - exact).norm() / exact.norm();
  const double error = (derived.gradient - exact).norm() / exact.norm();
  EXPECT_LT(error, 1.5 * floor) << "exact adjoint's error " << floor;
  EXPECT_GT((coarse.gradient - exact).norm() / exact.norm(), 3 * floor);
  EXPECT_LT(derived.iterations, fixed.iterations);
}

}  // namespace
}  // namespace diffpd
