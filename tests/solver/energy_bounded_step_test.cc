// One implicit step that cannot land on a stationary point above the previous
// total energy (solver/energy_bounded_step.h).
#include "solver/energy_bounded_step.h"

#include <gtest/gtest.h>

#include "test_scenes.h"

namespace diffpd {
namespace {

using internal::ImplicitSolver;
using internal::SimulatorImpl;
using internal::SolveEnergyBounded;
using internal::StepObjective;

Scene CubeScene() {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(2, 2, 2, 0.1, 0.1, 0.1);
  scene.material.youngs_modulus = 1e5;
  return scene;
}

SolverOptions Options(bool bound) {
  SolverOptions o;
  o.method = Method::kNewtonCholesky;
  o.time_step = 0.01;
  o.bound_step_energy = bound;
  return o;
}

VectorXd RestPositions(const SimulatorImpl& sim) {
  return Eigen::Map<const VectorXd>(sim.scene.mesh.vertices.data(), sim.num_dofs());
}

// A stand-in solver whose first call returns a far, strongly compressed
// point (g far above g(x_i)) reported as converged, as Newton did on the
// stress report's stiff cantilever, and whose later calls return their start.
struct FarThenStart {
  VectorXd far;
  std::vector<VectorXd> starts;
  ImplicitSolver solver() {
    return [this](StepObjective& objective, const VectorXd& x0, StepReport* report) -> VectorXd {
      starts.push_back(x0);
      VectorXd grad;
      objective.Evaluate(x0, &grad);
      report->initial_residual = objective.ReferenceResidual(grad.norm());
      report->iterations = 7;
      const VectorXd out = starts.size() == 1 ? far : x0;
      objective.Evaluate(out, &grad);
      report->final_residual = 1e-9;  // reported as converged, as Newton's far point was
      return out;
    };
  }
};

TEST(EnergyBoundedStepTest, ResolvesFromThePreviousStateWhenTheResultIsAboveItsEnergy) {
  SimulatorImpl sim(CubeScene(), Options(true));
  const VectorXd x = RestPositions(sim);
  // The objective's x_i + h v_i is a rigid shift of 2 mm; the solve's start
  // one of 1 mm (so that |grad g| there is the inertia's, not zero).
  const VectorXd predicted = x + VectorXd::Constant(x.size(), 1e-3);
  StepObjective objective(sim, x + VectorXd::Constant(x.size(), 2e-3), VectorXd::Zero(x.size()));
  FarThenStart solver{0.5 * x, {}};
  StepReport report;
  const VectorXd result = SolveEnergyBounded(objective, predicted, x, solver.solver(), &report);
  ASSERT_EQ(solver.starts.size(), 2u);
  EXPECT_EQ(solver.starts[0], predicted);
  EXPECT_EQ(solver.starts[1], x);  // the second solve starts at x_i
  EXPECT_EQ(result, x);
  EXPECT_EQ(report.energy_restarts, 1);
  EXPECT_EQ(report.iterations, 14);  // both solves counted
  // The second solve is judged against the first's reference residual.
  VectorXd grad;
  objective.Evaluate(predicted, &grad);
  EXPECT_NEAR(objective.ReferenceResidual(0.0), grad.norm(), 1e-9 * grad.norm());
  EXPECT_NEAR(report.initial_residual, grad.norm(), 1e-9 * grad.norm());
}

TEST(EnergyBoundedStepTest, KeepsAResultBelowThePreviousEnergy) {
  SimulatorImpl sim(CubeScene(), Options(true));
  const VectorXd x = RestPositions(sim);
  StepObjective objective(sim, x, VectorXd::Zero(x.size()));
  FarThenStart solver{x, {}};  // "far" is x_i itself: g(result) = g(x_i)
  StepReport report;
  SolveEnergyBounded(objective, x, x, solver.solver(), &report);
  EXPECT_EQ(solver.starts.size(), 1u);
  EXPECT_EQ(report.energy_restarts, 0);
}

// A converged result above g(x_i) only by the solve's tolerance (x_i itself
// nearly optimal, e.g. a body at rest) is not a far stationary point.
TEST(EnergyBoundedStepTest, ToleratesAnExcessWithinTheSolvesTolerance) {
  SimulatorImpl sim(CubeScene(), Options(true));
  const VectorXd x = RestPositions(sim);
  StepObjective objective(sim, x, VectorXd::Zero(x.size()));  // x_i is the minimiser: g(x_i) = 0
  VectorXd near = x;
  near(0) += 1e-9;  // g(near) > g(x_i) by ~|grad g| |near - x_i| / 2
  const ImplicitSolver solver = [&](StepObjective& o, const VectorXd&, StepReport* report) -> VectorXd {
    VectorXd grad;
    o.Evaluate(near, &grad);
    report->final_residual = grad.norm();
    return near;
  };
  StepReport report;
  EXPECT_EQ(SolveEnergyBounded(objective, x, x, solver, &report), near);
  EXPECT_EQ(report.energy_restarts, 0);
}

TEST(EnergyBoundedStepTest, OptionOffReturnsTheFirstResult) {
  SimulatorImpl sim(CubeScene(), Options(false));
  const VectorXd x = RestPositions(sim);
  StepObjective objective(sim, x, VectorXd::Zero(x.size()));
  FarThenStart solver{0.5 * x, {}};
  StepReport report;
  const VectorXd result = SolveEnergyBounded(objective, x, x, solver.solver(), &report);
  EXPECT_EQ(solver.starts.size(), 1u);
  EXPECT_EQ(result, 0.5 * x);
  EXPECT_EQ(report.energy_restarts, 0);
}

TEST(StepObjectiveTest, LastValueIsThatOfTheLatestEvaluationAtExactlyItsPoint) {
  SimulatorImpl sim(CubeScene(), Options(true));
  const VectorXd x = RestPositions(sim);
  StepObjective objective(sim, x, VectorXd::Zero(x.size()));
  double value = 0;
  EXPECT_FALSE(objective.LastValueAt(x, &value));
  VectorXd moved = 1.01 * x;
  const double g = objective.Evaluate(moved, nullptr);
  ASSERT_TRUE(objective.LastValueAt(moved, &value));
  EXPECT_EQ(value, g);
  EXPECT_FALSE(objective.LastValueAt(x, &value));
  moved(0) += 1e-12;
  EXPECT_FALSE(objective.LastValueAt(moved, &value));
}

}  // namespace
}  // namespace diffpd
