// RolloutCostFunction, AddMarkerResidualBlocks and RolloutEvaluationCallback
// (rollout_cost_function.h, rollout_evaluation_callback.h): the Ceres
// contract for unwanted Jacobians and row-major blocks, failing rollouts,
// one rollout per evaluation point shared by per-frame residual blocks, and
// argument checks. (Their derivatives: gradient_checker_test.cc.)
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include "diffpd/error.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "solvers/ceres/calibration_fixture.h"
#include "solvers/core/non_finite_pull_back_block.h"
#include "util/expect_message.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

std::vector<int> AllNodes(const Mesh& mesh) {
  std::vector<int> all(mesh.num_vertices());
  for (int i = 0; i < mesh.num_vertices(); ++i) all[i] = i;
  return all;
}

TEST(RolloutCostFunctionTest, HonoursUnwantedJacobiansAndRowMajorBlocks) {
  const SyntheticCalibration c = Synthetic(Method::kNewtonCholesky, true, MaterialParameters{1.5e5, 0.35, 1e3}, 4);
  auto f = c.MakeFunction(YoungsModulusAndPoissonsRatio());
  f->AddBlock(std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, AllNodes(c.scene.mesh)));
  const std::vector<std::vector<int>> frames = dynamic_cast<const MarkerResiduals&>(f->functional(0)).SamplesByFrame();
  ASSERT_GE(frames.size(), 2u);
  std::vector<int> rows;
  for (int s : frames[1])
    for (int d = 0; d < 3; ++d) rows.push_back(3 * s + d);
  RolloutCostFunction cost(f.get(), rows);  // one frame of 4 markers: 12 rows
  ASSERT_EQ(cost.num_residuals(), 12);
  ASSERT_EQ(cost.parameter_block_sizes(), (std::vector<int32_t>{2, 3}));
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
  EXPECT_EQ(j_material[0], -7.0);
  double* both[2] = {j_material.data(), j_velocity.data()};
  ASSERT_TRUE(cost.Evaluate(params, r2.data(), both));
  // Row-major: entry (row, col) at row * block_size + col, equal to the function's.
  VectorXd p(5), values;
  p << 1.5e5, 0.35, 0.01, -0.02, 0.03;
  MatrixXd j;
  ASSERT_TRUE(f->Evaluate(p, f->AllRows(), &values, &j));
  for (int row = 0; row < 12; ++row) {
    EXPECT_EQ(r[row], values(rows[row]));
    for (int col = 0; col < 2; ++col) EXPECT_EQ(j_material[row * 2 + col], j(rows[row], col));
    for (int col = 0; col < 3; ++col) EXPECT_EQ(j_velocity[row * 3 + col], j(rows[row], 2 + col));
  }
  EXPECT_EQ(f->statistics().rollouts, 1);  // the same point throughout: one rollout
  // One tangent pass (5 parameters, 12 rows: forward mode) gave every marker row.
  EXPECT_EQ(f->statistics().jacobians, 1);
  EXPECT_EQ(f->statistics().tangent_passes, 1);
}

TEST(RolloutCostFunctionTest, EvaluateReturnsFalseWhenTheRolloutFails) {
  SyntheticCalibration c = Synthetic(Method::kPd, true, TrueMaterial(), 4);
  c.options.max_iterations = 3;  // PD cannot converge in 3 iterations
  auto f = c.MakeFunction(YoungsModulusAndPoissonsRatio());
  RolloutCostFunction cost(f.get(), f->RowsOf(0));
  std::vector<double> r(cost.num_residuals());
  double material[2] = {2e5, 0.4};
  const double* params[1] = {material};
  EXPECT_FALSE(cost.Evaluate(params, r.data(), nullptr));
  EXPECT_EQ(f->statistics().failures, 1);
  EXPECT_EQ(f->statistics().last_error.rfind("rollout failed (maximum number of iterations reached): ", 0), 0u)
      << f->statistics().last_error;

  // Parameters outside the material's range: false, with the reason.
  auto ok = Synthetic(Method::kNewtonCholesky, true, TrueMaterial(), 4).MakeFunction(YoungsModulusAndPoissonsRatio());
  RolloutCostFunction ok_cost(ok.get(), ok->RowsOf(0));
  double bad[2] = {2e5, 0.5};
  const double* bad_params[1] = {bad};
  std::vector<double> j(2 * r.size());
  double* jac[1] = {j.data()};
  EXPECT_FALSE(ok_cost.Evaluate(bad_params, r.data(), jac));
  EXPECT_EQ(ok->statistics().last_error,
            "rollout rejected: poissons_ratio = 0.5 is invalid: must be finite and in (-1, 0.5)");
  double negative[2] = {-1.0, 0.3};
  const double* negative_params[1] = {negative};
  EXPECT_FALSE(ok_cost.Evaluate(negative_params, r.data(), nullptr));
  // A good point afterwards evaluates again.
  EXPECT_TRUE(ok_cost.Evaluate(params, r.data(), jac));
}

TEST(RolloutCostFunctionTest, ANonFiniteJacobianIsAFailedEvaluation) {
  // A material block whose reverse-mode derivative is NaN: residuals alone
  // evaluate; with Jacobians Evaluate returns false instead of passing NaN on.
  Scene scene = SmallBeamScene();
  RolloutFunction f(scene, TightOptions(Method::kNewtonCholesky), 3);
  f.AddBlock(std::make_unique<NonFinitePullBackBlock>(std::make_unique<MaterialBlock>(
      std::vector<MaterialBlock::Entry>{MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio}, scene)));
  f.AddFunctional(std::make_unique<PointCoordinate>(NodePoint(45, 44), 2, Vec3::UnitZ()));
  RolloutCostFunction cost(&f, f.AllRows());
  double material[2] = {2e5, 0.4};
  const double* params[1] = {material};
  double residual = 0;
  std::vector<double> j(2);
  double* jac[1] = {j.data()};
  EXPECT_TRUE(cost.Evaluate(params, &residual, nullptr));
  EXPECT_TRUE(std::isfinite(residual));
  EXPECT_FALSE(cost.Evaluate(params, &residual, jac));
  EXPECT_EQ(f.statistics().last_error,
            "Jacobian failed (non-finite value): row 0 (functional 'point_coordinate' value 0): the derivative with "
            "respect to parameter 0 = nan is not finite");
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

TEST(RolloutCostFunctionTest, PerFrameBlocksShareOneRolloutPerPointThroughTheCallback) {
  auto f = Synthetic(Method::kNewtonCholesky, false, MaterialParameters{1.2e5, 0.3, 1e3})
               .MakeFunction(YoungsModulusAndPoissonsRatio());
  double material[2] = {1.2e5, 0.3};
  CountingCallback callback(f.get(), {material});
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &callback;
  ceres::Problem problem(problem_options);
  const auto ids = AddMarkerResidualBlocks(&problem, f.get(), 0, {material});
  EXPECT_EQ(ids.size(), dynamic_cast<const MarkerResiduals&>(f->functional(0)).SamplesByFrame().size());
  EXPECT_GE(ids.size(), 5u);
  problem.SetManifold(material, new CoordinateManifold({CoordinateMap::Log(), CoordinateMap::Linear()}));
  problem.SetParameterLowerBound(material, 1, 0.1);
  problem.SetParameterUpperBound(material, 1, 0.49);
  ceres::Solver::Summary summary;
  ceres::Solve(TightRecoveryOptions(), &problem, &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  // Noise-free data from the true material: recovered to 1e-6.
  EXPECT_NEAR(material[0], 2e5, 1e-6 * 2e5) << summary.FullReport();
  EXPECT_NEAR(material[1], 0.4, 1e-6 * 0.4);
  // At most one rollout per new evaluation point that Ceres announced
  // (Ceres may announce the same values twice; the cache runs them once),
  // although every point evaluates every frame's block; at most one
  // Jacobian computation per announced Jacobian request.
  EXPECT_GT(f->statistics().rollouts, 5);
  EXPECT_LE(f->statistics().rollouts, callback.new_points);
  EXPECT_LE(f->statistics().jacobians, callback.jacobian_requests);
  EXPECT_LT(f->statistics().rollouts, summary.num_residual_evaluations * static_cast<long>(ids.size()));
  EXPECT_EQ(f->statistics().failures, 0);
}

TEST(RolloutCostFunctionTest, BadArgumentsAreRefusedWithMessages) {
  auto f = Synthetic(Method::kNewtonCholesky, true, TrueMaterial(), 4).MakeFunction(YoungsModulusAndPoissonsRatio());
  const int rows = f->num_rows();
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { RolloutCostFunction(f.get(), {}); }), "RolloutCostFunction: no row");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { RolloutCostFunction(f.get(), {rows}); }),
            "RolloutCostFunction: row " + std::to_string(rows) + " is out of range [0, " + std::to_string(rows) + ")");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              RolloutCostFunction(f.get(), {1, 3, 1});
            }),
            "RolloutCostFunction: row 1 is listed twice");
  double a[2], b[3];
  ceres::Problem problem;
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              AddMarkerResidualBlocks(&problem, f.get(), 0, {a, b});
            }),
            "AddMarkerResidualBlocks: got 2 parameter blocks, the rollout function has 1");
  EXPECT_EQ(MessageOf<InvalidInputError>([&] {
              RolloutEvaluationCallback(f.get(), {a, b});
            }),
            "RolloutEvaluationCallback: got 2 parameter blocks, the rollout function has 1");
  f->AddFunctional(
      std::make_unique<PointCoordinate>(NodePoint(f->scene().mesh.num_vertices(), 0), 2, Vec3::UnitZ(), "tip"));
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { AddMarkerResidualBlocks(&problem, f.get(), 1, {a}); }),
            "AddMarkerResidualBlocks: functional 1 ('tip') is not a MarkerResiduals");
  RolloutFunction no_blocks(SmallBeamScene(), TightOptions(Method::kNewtonCholesky), 2);
  no_blocks.AddFunctional(std::make_unique<PointCoordinate>(NodePoint(45, 44), 2, Vec3::UnitZ()));
  EXPECT_EQ(MessageOf<InvalidInputError>([&] { RolloutCostFunction(&no_blocks, {0}); }),
            "RolloutCostFunction: the rollout function has no parameter block");
}

}  // namespace
}  // namespace diffpd::testing
