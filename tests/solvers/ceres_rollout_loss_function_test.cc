// RolloutLossFunction (rollout_loss_function.h): its gradient is J^T r of
// the forward-mode Jacobian and matches central differences; a custom
// trajectory loss; ceres::GradientProblem recovers the true material;
// failures return false.
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include "ceres_calibration_fixture.h"
#include "diffpd/error.h"
#include "diffpd/solvers/coordinate_manifold.h"
#include "diffpd/solvers/rollout_loss_function.h"

namespace diffpd::solvers {
namespace {

TEST(RolloutLossFunctionTest, GradientIsJacobianTransposeResidualAndMatchesFiniteDifferences) {
  CalibrationSetup setup = testing::SyntheticSetup(Method::kNewtonCholesky, true, testing::TrueMaterial(), 6);
  setup.fitted = {MaterialParameter::kYoungsModulus, MaterialParameter::kPoissonsRatio, MaterialParameter::kDensity};
  setup.input_parameters = std::make_shared<LinearInputParameters>(
      LinearInputParameters::UniformInitialVelocity(setup.scene.mesh.num_vertices()));
  CalibrationModel model(setup);
  RolloutLossFunction f(&model);
  ASSERT_EQ(f.NumParameters(), 6);
  std::vector<double> x = {1.6e5, 0.35, 900, 0.01, 0.02, -0.03};
  double cost = 0;
  std::vector<double> grad(6);
  ASSERT_TRUE(f.Evaluate(x.data(), &cost, grad.data()));
  const double* blocks[2] = {x.data(), x.data() + 3};
  ASSERT_TRUE(model.Evaluate(blocks, true));
  EXPECT_NEAR(cost, 0.5 * model.residuals().squaredNorm(), 1e-14 * cost);
  VectorXd jtr(6);
  jtr << model.jacobian(0).transpose() * model.residuals(), model.jacobian(1).transpose() * model.residuals();
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(grad[i], jtr(i), 1e-9 * std::abs(jtr(i))) << i;
    const double saved = x[i];
    // Steps above the solves' noise floor: for the small initial velocities
    // (0.01-0.03 m/s) a step of 1e-7 m/s left the quotient at 1.5e-6 from the
    // gradient through rounding alone (1.2e-9 at 1e-5 m/s, 1.6e-10 at 1e-4).
    const double eps = 1e-5 * std::max(std::abs(saved), 1.0);
    double plus = 0, minus = 0;
    x[i] = saved + eps;
    ASSERT_TRUE(f.Evaluate(x.data(), &plus, nullptr));
    x[i] = saved - eps;
    ASSERT_TRUE(f.Evaluate(x.data(), &minus, nullptr));
    x[i] = saved;
    EXPECT_NEAR(grad[i], (plus - minus) / (2 * eps), 1e-6 * std::abs(grad[i])) << i;
  }
  EXPECT_EQ(model.statistics().gradients, 1);
}

TEST(RolloutLossFunctionTest, CustomLossOfTheFinalStateMatchesFiniteDifferences) {
  CalibrationSetup setup = testing::SyntheticSetup(Method::kPd, true, testing::TrueMaterial(), 4);
  CalibrationModel model(setup);
  // L = 1/2 |x_K - rest|^2: how far the beam is from rest at the end.
  const VectorXd rest = Eigen::Map<const VectorXd>(setup.scene.mesh.vertices.data(), setup.scene.mesh.num_dofs());
  RolloutLossFunction f(&model, [rest](const Rollout& r, LossGradient* g) {
    const VectorXd d = r.states.back().x - rest;
    g->dx.back() = d;
    return 0.5 * d.squaredNorm();
  });
  std::vector<double> x = {2.2e5, 0.38};
  double cost = 0, plus = 0, minus = 0;
  double grad[2];
  ASSERT_TRUE(f.Evaluate(x.data(), &cost, grad));
  EXPECT_GT(cost, 0);
  for (int i = 0; i < 2; ++i) {
    const double saved = x[i], eps = 1e-5 * saved;
    x[i] = saved + eps;
    ASSERT_TRUE(f.Evaluate(x.data(), &plus, nullptr));
    x[i] = saved - eps;
    ASSERT_TRUE(f.Evaluate(x.data(), &minus, nullptr));
    x[i] = saved;
    EXPECT_NEAR(grad[i], (plus - minus) / (2 * eps), 1e-6 * std::abs(grad[i])) << i;
  }
}

TEST(RolloutLossFunctionTest, GradientProblemRecoversTheTrueMaterial) {
  // Residuals in metres (unit weights): line searches start with a step of
  // the gradient's size, so the loss should be O(1) or smaller.
  CalibrationSetup setup =
      testing::SyntheticSetup(Method::kNewtonCholesky, false, MaterialParameters{1.4e5, 0.33, 1e3});
  for (MarkerSample& s : setup.motion.samples) s.weight = Vec3::Ones();
  CalibrationModel model(setup);
  double x[2];
  model.InitialMaterialBlock(x);
  ceres::GradientProblem problem(new RolloutLossFunction(&model),
                                 new CoordinateManifold({CoordinateMap::Log(), CoordinateMap::Logit(0, 0.5)}));
  ceres::GradientProblemSolver::Options options;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-14;
  options.parameter_tolerance = 1e-14;
  ceres::GradientProblemSolver::Summary summary;
  ceres::Solve(options, problem, x, &summary);
  EXPECT_NEAR(x[0] / 2e5, 1.0, 1e-6) << summary.FullReport();
  EXPECT_NEAR(x[1] / 0.4, 1.0, 1e-6) << summary.FullReport();
}

TEST(RolloutLossFunctionTest, ReturnsFalseOnAFailingRollout) {
  CalibrationModel model(testing::SyntheticSetup(Method::kNewtonCholesky, true, testing::TrueMaterial(), 4));
  RolloutLossFunction f(&model);
  double x[2] = {2e5, 0.7};
  double cost = 0, grad[2];
  EXPECT_FALSE(f.Evaluate(x, &cost, grad));
  EXPECT_EQ(model.statistics().last_error,
            "rollout rejected: poissons_ratio = 0.7 is invalid: must be finite and in (-1, 0.5)");
  // A loss that throws is reported, not propagated.
  RolloutLossFunction throwing(
      &model, [](const Rollout&, LossGradient*) -> double { throw SolverError(SolverStatus::kNonFinite, "bad loss"); });
  x[1] = 0.4;
  EXPECT_FALSE(throwing.Evaluate(x, &cost, grad));
  EXPECT_EQ(model.statistics().last_error, "loss gradient failed (non-finite value): bad loss");
}

}  // namespace
}  // namespace diffpd::solvers
