// RolloutLossFunction (rollout_loss_function.h): the gradient of the
// least-squares marker loss is J^T r of the forward-mode Jacobian and matches
// central differences; a loss of the final state; ceres::GradientProblem
// recovers the true material; failures return false; argument checks.
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include "diffpd/error.h"
#include "diffpd/solvers/ceres/rollout_loss_function.h"
#include "diffpd/solvers/core/initial_state_block.h"
#include "diffpd/solvers/core/least_squares_loss.h"
#include "solvers/ceres/calibration_fixture.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

// Adds the least-squares loss of the synthetic motion; returns its index.
int AddMarkerLoss(const SyntheticCalibration& c, RolloutFunction* f) {
  return f->AddFunctional(std::make_unique<LeastSquaresLoss>(
      std::make_unique<MarkerResiduals>(c.motion, c.scene.mesh, c.options.time_step, c.steps)));
}

TEST(RolloutLossFunctionTest, GradientIsJacobianTransposeResidualAndMatchesFiniteDifferences) {
  const SyntheticCalibration c = Synthetic(Method::kNewtonCholesky, true, TrueMaterial(), 6);
  auto f = c.MakeFunction({MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio, MaterialField::kDensity});
  std::vector<int> all(c.scene.mesh.num_vertices());
  for (int i = 0; i < c.scene.mesh.num_vertices(); ++i) all[i] = i;
  f->AddBlock(std::make_unique<InitialStateBlock>(InitialStateBlock::kVelocity, all));
  const int loss = AddMarkerLoss(c, f.get());
  RolloutLossFunction fn(f.get(), loss);
  ASSERT_EQ(fn.NumParameters(), 6);
  std::vector<double> x = {1.6e5, 0.35, 900, 0.01, 0.02, -0.03};
  double cost = 0;
  std::vector<double> grad(6);
  ASSERT_TRUE(fn.Evaluate(x.data(), &cost, grad.data()));
  const Eigen::Map<const VectorXd> p(x.data(), 6);
  VectorXd r;
  MatrixXd j;
  f->SetDerivativeMode(DerivativeMode::kForward);
  ASSERT_TRUE(f->Evaluate(p, f->RowsOf(0), &r, &j));
  EXPECT_NEAR(cost, 0.5 * r.squaredNorm(), 1e-14 * cost);
  const VectorXd jtr = j.transpose() * r;
  for (int i = 0; i < 6; ++i) {
    EXPECT_NEAR(grad[i], jtr(i), 1e-9 * std::abs(jtr(i))) << i;
    const double saved = x[i];
    // Steps above the solves' noise floor: for the small initial velocities
    // (0.01-0.03 m/s) a step of 1e-7 m/s left the quotient at 1.5e-6 from the
    // gradient through rounding alone (1.2e-9 at 1e-5 m/s, 1.6e-10 at 1e-4).
    const double eps = 1e-5 * std::max(std::abs(saved), 1.0);
    double plus = 0, minus = 0;
    x[i] = saved + eps;
    ASSERT_TRUE(fn.Evaluate(x.data(), &plus, nullptr));
    x[i] = saved - eps;
    ASSERT_TRUE(fn.Evaluate(x.data(), &minus, nullptr));
    x[i] = saved;
    EXPECT_NEAR(grad[i], (plus - minus) / (2 * eps), 1e-6 * std::abs(grad[i])) << i;
  }
  EXPECT_EQ(f->statistics().gradients, 1);
}

// L = 1/2 |x_K - rest|^2: how far the beam is from rest at the end.
class DistanceFromRest : public TrajectoryFunction {
 public:
  explicit DistanceFromRest(VectorXd rest) : rest_(std::move(rest)) {}
  std::string name() const override { return "distance_from_rest"; }
  int LastState(int num_steps) const override { return num_steps; }
  double Value(const Rollout& r) const override { return 0.5 * (r.states.back().x - rest_).squaredNorm(); }
  void AddGradient(const Rollout& r, double weight, LossGradient* loss) const override {
    loss->dx.back() = weight * (r.states.back().x - rest_);
  }

 private:
  VectorXd rest_;
};

TEST(RolloutLossFunctionTest, LossOfTheFinalStateMatchesFiniteDifferences) {
  const SyntheticCalibration c = Synthetic(Method::kPd, true, TrueMaterial(), 4);
  auto f = c.MakeFunction(YoungsModulusAndPoissonsRatio());
  const int loss = f->AddFunctional(std::make_unique<DistanceFromRest>(
      Eigen::Map<const VectorXd>(c.scene.mesh.vertices.data(), c.scene.mesh.num_dofs())));
  RolloutLossFunction fn(f.get(), loss);
  std::vector<double> x = {2.2e5, 0.38};
  double cost = 0, plus = 0, minus = 0;
  double grad[2];
  ASSERT_TRUE(fn.Evaluate(x.data(), &cost, grad));
  EXPECT_GT(cost, 0);
  for (int i = 0; i < 2; ++i) {
    const double saved = x[i], eps = 1e-5 * saved;
    x[i] = saved + eps;
    ASSERT_TRUE(fn.Evaluate(x.data(), &plus, nullptr));
    x[i] = saved - eps;
    ASSERT_TRUE(fn.Evaluate(x.data(), &minus, nullptr));
    x[i] = saved;
    EXPECT_NEAR(grad[i], (plus - minus) / (2 * eps), 1e-6 * std::abs(grad[i])) << i;
  }
}

TEST(RolloutLossFunctionTest, GradientProblemRecoversTheTrueMaterial) {
  // Residuals in metres (unit weights): line searches start with a step of
  // the gradient's size, so the loss should be O(1) or smaller.
  SyntheticCalibration c = Synthetic(Method::kNewtonCholesky, false, MaterialParameters{1.4e5, 0.33, 1e3});
  for (MarkerSample& s : c.motion.samples) s.weight = Vec3::Ones();
  auto f = c.MakeFunction(YoungsModulusAndPoissonsRatio());
  const int loss = AddMarkerLoss(c, f.get());
  double x[2] = {1.4e5, 0.33};
  ceres::GradientProblem problem(new RolloutLossFunction(f.get(), loss),
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

// A loss whose evaluation throws.
class ThrowingLoss : public TrajectoryFunction {
 public:
  std::string name() const override { return "throwing"; }
  int LastState(int num_steps) const override { return num_steps; }
  double Value(const Rollout& r) const override { throw SolverError(SolverStatus::kNonFinite, "bad loss"); }
  void AddGradient(const Rollout& r, double weight, LossGradient* loss) const override {}
};

TEST(RolloutLossFunctionTest, ReturnsFalseOnAFailingRolloutOrLoss) {
  const SyntheticCalibration c = Synthetic(Method::kNewtonCholesky, true, TrueMaterial(), 4);
  auto f = c.MakeFunction(YoungsModulusAndPoissonsRatio());
  RolloutLossFunction fn(f.get(), AddMarkerLoss(c, f.get()));
  double x[2] = {2e5, 0.7};
  double cost = 0, grad[2];
  EXPECT_FALSE(fn.Evaluate(x, &cost, grad));
  EXPECT_EQ(f->statistics().last_error,
            "rollout rejected: poissons_ratio = 0.7 is invalid: must be finite and in (-1, 0.5)");
  // A loss that throws is reported, not propagated.
  auto g = c.MakeFunction(YoungsModulusAndPoissonsRatio());
  RolloutLossFunction throwing(g.get(), g->AddFunctional(std::make_unique<ThrowingLoss>()));
  x[1] = 0.4;
  EXPECT_FALSE(throwing.Evaluate(x, &cost, grad));
  EXPECT_EQ(g->statistics().last_error, "values failed (non-finite value): bad loss");
  // Only scalar functionals are losses.
  try {
    RolloutLossFunction(f.get(), 0);
    ADD_FAILURE() << "no throw";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(std::string(e.what()), "RolloutLossFunction: functional 0 ('marker_residuals') has " +
                                         std::to_string(f->functional(0).num_values()) + " values, expected 1");
  }
  EXPECT_THROW(RolloutLossFunction(f.get(), 2), InvalidInputError);
}

}  // namespace
}  // namespace diffpd::testing
