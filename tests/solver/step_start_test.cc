// Where an implicit step's solve starts: x_i + h v_i, or x_i where g is lower
// there (solver/step_start.h).
#include "solver/step_start.h"

#include <gtest/gtest.h>

#include "test_scenes.h"

namespace diffpd {
namespace {

using internal::ChooseStepStart;
using internal::SimulatorImpl;
using internal::StepObjective;

Scene CubeScene(double youngs_modulus, bool gravity) {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(2, 2, 2, 0.1, 0.1, 0.1);
  scene.material.youngs_modulus = youngs_modulus;
  scene.material.poissons_ratio = 0.45;
  if (gravity) scene.gravity = Vec3(0, 0, -9.81);
  return scene;
}

SolverOptions Options() {
  SolverOptions o;
  o.method = Method::kNewtonCholesky;
  o.time_step = 0.01;
  return o;
}

// A stiff cube at rest shape moving inward at 1 m/s per m from its centre:
// the predictor is compressed by 1%, its elastic energy (~1e3 J) far above
// the kinetic energy (~1e-3 J), so g(x_i) < g(x_i + h v_i).
TEST(StepStartTest, StartsFromThePreviousStateWhereThePredictorHoldsMoreThanItsTotalEnergy) {
  SimulatorImpl sim(CubeScene(1e10, false), Options());
  const VectorXd x = Eigen::Map<const VectorXd>(sim.scene.mesh.vertices.data(), sim.num_dofs());
  VectorXd v(x.size());
  for (int i = 0; i < x.size(); ++i) v(i) = -(x(i) - 0.05);
  const VectorXd predicted = x + sim.h() * v;
  StepObjective objective(sim, predicted, VectorXd::Zero(x.size()));
  VectorXd predicted_grad, previous_grad;
  const double predicted_value = objective.Evaluate(predicted, &predicted_grad);
  const double previous_value = objective.Evaluate(x, &previous_grad);
  ASSERT_LT(previous_value, 1e-3 * predicted_value);

  const VectorXd start = ChooseStepStart(objective, predicted, x);
  EXPECT_EQ(start, x);
  // The convergence test stays relative to the predictor's residual (to
  // rounding: the SVDs' warm starts differ between the evaluations).
  EXPECT_NEAR(objective.ReferenceResidual(0.0), predicted_grad.norm(), 1e-12 * predicted_grad.norm());
  // The start's evaluation is primed: the solver's first Evaluate returns it.
  VectorXd primed_grad;
  EXPECT_NEAR(objective.Evaluate(start, &primed_grad), previous_value, 1e-9 * std::abs(previous_value));
  EXPECT_LE((primed_grad - previous_grad).norm(), 1e-6 * previous_grad.norm());
}

// With SolverOptions::start_at_lower_energy = false the same case starts at
// the predictor, without evaluating anything.
TEST(StepStartTest, OptionOffStartsAtThePredictor) {
  SolverOptions options = Options();
  options.start_at_lower_energy = false;
  SimulatorImpl sim(CubeScene(1e10, false), options);
  const VectorXd x = Eigen::Map<const VectorXd>(sim.scene.mesh.vertices.data(), sim.num_dofs());
  VectorXd v(x.size());
  for (int i = 0; i < x.size(); ++i) v(i) = -(x(i) - 0.05);
  const VectorXd predicted = x + sim.h() * v;
  StepObjective objective(sim, predicted, VectorXd::Zero(x.size()));
  EXPECT_EQ(ChooseStepStart(objective, predicted, x), predicted);
  EXPECT_EQ(objective.ReferenceResidual(123.0), 123.0);  // no reference set: the start's own
}

// Free fall: the predictor is lower in the gravity potential by h m g |v|
// than x_i is in kinetic energy above it, so the solve starts there as before.
TEST(StepStartTest, StartsFromThePredictorInFreeFall) {
  SimulatorImpl sim(CubeScene(1e5, true), Options());
  const int n = sim.num_dofs();
  const VectorXd x = Eigen::Map<const VectorXd>(sim.scene.mesh.vertices.data(), n);
  VectorXd v = VectorXd::Zero(n);
  for (int i = 0; i < n / 3; ++i) v(3 * i + 2) = -1.0;
  const VectorXd predicted = x + sim.h() * v;
  StepObjective objective(sim, predicted, sim.ExplicitForce(StepInput()));
  const VectorXd start = ChooseStepStart(objective, predicted, x);
  EXPECT_EQ(start, predicted);
  VectorXd grad;
  objective.Evaluate(predicted, &grad);
  EXPECT_NEAR(objective.ReferenceResidual(0.0), grad.norm(), 1e-12 * grad.norm());
}

// A primed evaluation is used once, and only at exactly its point.
TEST(StepStartTest, PrimedEvaluationIsUsedOnceAndOnlyAtItsPoint) {
  SimulatorImpl sim(CubeScene(1e5, false), Options());
  const int n = sim.num_dofs();
  const VectorXd x = Eigen::Map<const VectorXd>(sim.scene.mesh.vertices.data(), n);
  StepObjective objective(sim, x, VectorXd::Zero(n));
  const VectorXd marker = VectorXd::Constant(n, 7.0);
  objective.Prime(x, 42.0, marker);
  VectorXd grad;
  EXPECT_EQ(objective.Evaluate(x, &grad), 42.0);
  EXPECT_EQ(grad, marker);
  EXPECT_NE(objective.Evaluate(x, &grad), 42.0);  // used up: recomputed
  objective.Prime(x, 42.0, marker);
  VectorXd moved = x;
  moved(0) += 1e-6;
  EXPECT_NE(objective.Evaluate(moved, &grad), 42.0);  // another point: recomputed
  EXPECT_NE(objective.Evaluate(x, &grad), 42.0);      // and the prime is gone
}

}  // namespace
}  // namespace diffpd
