// MarkerCostFunction and RolloutEvaluationCallback (marker_cost_function.h):
// ceres::GradientChecker at random parameter values in forward and reverse
// mode, the Ceres contract for unwanted Jacobians, failing rollouts, and one
// rollout per evaluation point shared by per-frame residual blocks.
#include <gtest/gtest.h>

#include <random>

#include <ceres/ceres.h>
#include <ceres/gradient_checker.h>

#include "ceres_calibration_fixture.h"
#include "diffpd/solvers/coordinate_manifold.h"
#include "diffpd/solvers/marker_cost_function.h"

namespace diffpd::solvers {
namespace {

struct CheckCase {
  Method method;
  bool tets;
  JacobianMode mode;
  bool input_block;  // add a uniform initial velocity block
};

std::string CheckCaseName(const ::testing::TestParamInfo<CheckCase>& info) {
  std::string name = ToString(info.param.method);
  for (char& ch : name)
    if (ch == '-') ch = '_';
  name += info.param.tets ? "_tet" : "_hex";
  name += info.param.mode == JacobianMode::kForward ? "_forward" : "_reverse";
  return name + (info.param.input_block ? "_with_velocity" : "");
}

class MarkerCostFunctionCheckTest : public ::testing::TestWithParam<CheckCase> {};

TEST_P(MarkerCostFunctionCheckTest, GradientCheckerAcceptsRandomParameterValues) {
  const CheckCase c = GetParam();
  CalibrationSetup setup = testing::SyntheticSetup(c.method, c.tets, testing::TrueMaterial(), c.input_block ? 4 : 6);
  setup.fitted = {MaterialParameter::kYoungsModulus, MaterialParameter::kPoissonsRatio};
  if (c.input_block) {
    setup.fitted.push_back(MaterialParameter::kDensity);
    setup.input_parameters = std::make_shared<LinearInputParameters>(
        LinearInputParameters::UniformInitialVelocity(setup.scene.mesh.num_vertices()));
  }
  setup.jacobian = c.mode;
  CalibrationModel model(setup);
  MarkerCostFunction cost(&model);
  ASSERT_EQ(cost.num_residuals(), model.num_residuals());
  std::vector<CoordinateMap> maps = {CoordinateMap::Log(), CoordinateMap::Logit(0, 0.5)};
  if (c.input_block) maps.push_back(CoordinateMap::Log());
  const CoordinateManifold log_material(maps);
  std::vector<const ceres::Manifold*> manifolds = {&log_material};
  if (c.input_block) manifolds.push_back(nullptr);
  ceres::NumericDiffOptions numeric;
  numeric.relative_step_size = 1e-5;
  numeric.ridders_relative_initial_step_size = 1e-3;  // GradientChecker uses Ridders: start near nu
  ceres::GradientChecker checker(&cost, &manifolds, numeric);
  std::mt19937_64 rng(c.input_block ? 3 : 5);
  std::uniform_real_distribution<double> u(0, 1);
  // PD's forward solves converge linearly: its finite differences are noisier.
  const double precision = c.method == Method::kPd ? 5e-5 : 1e-6;
  const int points = c.method == Method::kNewtonCholesky && !c.input_block ? 2 : 1;
  for (int point = 0; point < points; ++point) {
    std::vector<double> material = {1e5 + 3e5 * u(rng), 0.25 + 0.2 * u(rng)};
    if (c.input_block) material.push_back(800 + 400 * u(rng));
    std::vector<double> velocity = {0.2 * u(rng) - 0.1, 0.2 * u(rng) - 0.1, 0.2 * u(rng) - 0.1};
    std::vector<double*> blocks = {material.data()};
    if (c.input_block) blocks.push_back(velocity.data());
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(blocks.data(), precision, &results))
        << results.error_log << "\nlast model error: " << model.statistics().last_error;
    EXPECT_LT(results.maximum_relative_error, precision);
    EXPECT_TRUE(results.return_value);
  }
}

INSTANTIATE_TEST_SUITE_P(MethodsAndModes, MarkerCostFunctionCheckTest,
                         ::testing::Values(CheckCase{Method::kNewtonCholesky, false, JacobianMode::kForward, true},
                                           CheckCase{Method::kNewtonCholesky, true, JacobianMode::kReverse, true},
                                           CheckCase{Method::kNewtonCholesky, true, JacobianMode::kForward, false},
                                           CheckCase{Method::kPd, true, JacobianMode::kForward, false}),
                         CheckCaseName);

TEST(MarkerCostFunctionTest, HonoursUnwantedJacobiansAndRowMajorBlocks) {
  CalibrationSetup setup =
      testing::SyntheticSetup(Method::kNewtonCholesky, true, MaterialParameters{1.5e5, 0.35, 1e3}, 4);
  setup.input_parameters = std::make_shared<LinearInputParameters>(
      LinearInputParameters::UniformInitialVelocity(setup.scene.mesh.num_vertices()));
  CalibrationModel model(setup);
  const std::vector<std::vector<int>> frames = model.SamplesByFrame();
  ASSERT_GE(frames.size(), 2u);
  MarkerCostFunction cost(&model, frames[1]);  // one frame of 4 markers: 12 rows
  ASSERT_EQ(cost.num_residuals(), 12);
  double material[2] = {1.5e5, 0.35};
  double velocity[3] = {0.01, -0.02, 0.03};
  const double* params[2] = {material, velocity};
  std::vector<double> r(12), r2(12), j_material(24, -7.0), j_velocity(36, -7.0);
  // No Jacobians at all.
  ASSERT_TRUE(cost.Evaluate(params, r.data(), nullptr));
  // Only the second block's Jacobian: the first is not touched.
  double* only_velocity[2] = {nullptr, j_velocity.data()};
  ASSERT_TRUE(cost.Evaluate(params, r2.data(), only_velocity));
  EXPECT_EQ(r, r2);
  EXPECT_NE(j_velocity[0], -7.0);
  double* both[2] = {j_material.data(), j_velocity.data()};
  ASSERT_TRUE(cost.Evaluate(params, r2.data(), both));
  // Row-major: entry (row, col) at row * block_size + col, equal to the model's.
  for (int row = 0; row < 12; ++row) {
    const int model_row = 3 * frames[1][row / 3] + row % 3;
    EXPECT_EQ(r[row], model.residuals()(model_row));
    for (int col = 0; col < 2; ++col) EXPECT_EQ(j_material[row * 2 + col], model.jacobian(0)(model_row, col));
    for (int col = 0; col < 3; ++col) EXPECT_EQ(j_velocity[row * 3 + col], model.jacobian(1)(model_row, col));
  }
  EXPECT_EQ(model.statistics().rollouts, 1);  // the same point thrice: one rollout
  EXPECT_EQ(model.statistics().jacobians, 1);
}

TEST(MarkerCostFunctionTest, EvaluateReturnsFalseWhenTheRolloutFails) {
  CalibrationSetup setup = testing::SyntheticSetup(Method::kPd, true, testing::TrueMaterial(), 4);
  setup.solver.max_iterations = 3;  // PD cannot converge in 3 iterations
  CalibrationModel model(setup);
  MarkerCostFunction cost(&model);
  std::vector<double> r(cost.num_residuals());
  double material[2] = {2e5, 0.4};
  const double* params[1] = {material};
  EXPECT_FALSE(cost.Evaluate(params, r.data(), nullptr));
  EXPECT_EQ(model.statistics().failures, 1);
  EXPECT_EQ(model.statistics().last_error.rfind("rollout failed (maximum number of iterations reached): ", 0), 0u)
      << model.statistics().last_error;

  // Parameters outside the material's range: false, with the reason.
  CalibrationModel ok_model(testing::SyntheticSetup(Method::kNewtonCholesky, true, testing::TrueMaterial(), 4));
  MarkerCostFunction ok_cost(&ok_model);
  double bad[2] = {2e5, 0.5};
  const double* bad_params[1] = {bad};
  std::vector<double> j(2 * r.size());
  double* jac[1] = {j.data()};
  EXPECT_FALSE(ok_cost.Evaluate(bad_params, r.data(), jac));
  EXPECT_EQ(ok_model.statistics().last_error,
            "rollout rejected: poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");
  double negative[2] = {-1.0, 0.3};
  const double* negative_params[1] = {negative};
  EXPECT_FALSE(ok_cost.Evaluate(negative_params, r.data(), nullptr));
  // A good point afterwards evaluates again.
  EXPECT_TRUE(ok_cost.Evaluate(params, r.data(), jac));
}

// Counts what Ceres announces.
class CountingCallback : public RolloutEvaluationCallback {
 public:
  using RolloutEvaluationCallback::RolloutEvaluationCallback;
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override {
    new_points += new_evaluation_point;
    jacobian_requests += evaluate_jacobians;
    RolloutEvaluationCallback::PrepareForEvaluation(evaluate_jacobians, new_evaluation_point);
  }
  int new_points = 0;
  int jacobian_requests = 0;
};

TEST(MarkerCostFunctionTest, PerFrameBlocksShareOneRolloutPerPointThroughTheCallback) {
  CalibrationSetup setup = testing::SyntheticSetup(Method::kNewtonCholesky, false, MaterialParameters{1.2e5, 0.3, 1e3});
  CalibrationModel model(setup);
  double material[2];
  model.InitialMaterialBlock(material);
  CountingCallback callback(&model, {material});
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &callback;
  ceres::Problem problem(problem_options);
  const auto ids = AddMarkerResidualBlocks(&problem, &model, {material});
  EXPECT_EQ(ids.size(), model.SamplesByFrame().size());
  EXPECT_GE(ids.size(), 5u);
  problem.SetManifold(material, new CoordinateManifold({CoordinateMap::Log(), CoordinateMap::Linear()}));
  problem.SetParameterLowerBound(material, 1, 0.1);
  problem.SetParameterUpperBound(material, 1, 0.49);
  const ceres::Solver::Options options = testing::TightRecoveryOptions();
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  // Noise-free data from the true material: recovered to 1e-6.
  EXPECT_NEAR(material[0], 2e5, 1e-6 * 2e5) << summary.FullReport();
  EXPECT_NEAR(material[1], 0.4, 1e-6 * 0.4);
  // At most one rollout per new evaluation point that Ceres announced
  // (Ceres may announce the same values twice; the cache runs them once),
  // although every point evaluates every frame's block; at most one
  // derivative per announced Jacobian request.
  EXPECT_GT(model.statistics().rollouts, 5);
  EXPECT_LE(model.statistics().rollouts, callback.new_points);
  EXPECT_LE(model.statistics().jacobians, callback.jacobian_requests);
  EXPECT_LT(model.statistics().rollouts, summary.num_residual_evaluations * static_cast<int>(ids.size()));
  EXPECT_EQ(model.statistics().failures, 0);
}

}  // namespace
}  // namespace diffpd::solvers
