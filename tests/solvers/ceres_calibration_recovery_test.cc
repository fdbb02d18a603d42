// Synthetic recovery of known material parameters with Ceres through the
// calibration adapters (calibration_model.h, marker_cost_function.h): exact
// recovery from noise-free motion with PD and Newton-Cholesky, and errors
// within the linearised spread of the noise with noisy motion.
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include "ceres_calibration_fixture.h"
#include "diffpd/solvers/coordinate_manifold.h"
#include "diffpd/solvers/marker_cost_function.h"

namespace diffpd::solvers {
namespace {

struct RecoveryResult {
  double youngs_modulus, poissons_ratio;
  ceres::Solver::Summary summary;
};

RecoveryResult Recover(const CalibrationSetup& setup) {
  RecoveryResult out;
  const std::vector<double> material = testing::FitMaterialBlock(setup, &out.summary);
  out.youngs_modulus = material[0];
  out.poissons_ratio = material[1];
  return out;
}

TEST(CalibrationRecoveryTest, RecoversTrueMaterialFromNoiseFreeMotionWithPdAndNewton) {
  for (auto [method, tets] : {std::pair{Method::kNewtonCholesky, false}, std::pair{Method::kPd, true}}) {
    const RecoveryResult r = Recover(testing::SyntheticSetup(method, tets, MaterialParameters{1e5, 0.3, 1e3}));
    ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.FullReport();
    EXPECT_NEAR(r.youngs_modulus / 2e5, 1.0, 1e-6) << ToString(method) << "\n" << r.summary.FullReport();
    EXPECT_NEAR(r.poissons_ratio / 0.4, 1.0, 1e-6) << ToString(method);
    EXPECT_LT(r.summary.final_cost, 1e-12);
  }
}

TEST(CalibrationRecoveryTest, NoisyMotionGivesErrorsWithinTheNoisesLinearisedSpread) {
  // 0.05 mm of Gaussian noise: the fitted material lies within 4 standard
  // deviations of the truth, the deviations from the Gauss-Newton covariance
  // at the solution, Cov = (J^T J)^-1 J^T diag(w^2 sigma^2) J (J^T J)^-1,
  // and the unweighted marker RMS error matches the noise.
  const double noise = 5e-5;
  const CalibrationSetup setup =
      testing::SyntheticSetup(Method::kNewtonCholesky, false, MaterialParameters{1e5, 0.3, 1e3}, 8, noise);
  const RecoveryResult r = Recover(setup);
  ASSERT_TRUE(r.summary.IsSolutionUsable());
  CalibrationModel model(setup);
  double fitted[2] = {r.youngs_modulus, r.poissons_ratio};
  const double* blocks[1] = {fitted};
  ASSERT_TRUE(model.Evaluate(blocks, true));
  const MatrixXd& j = model.jacobian(0);
  VectorXd w2(j.rows());
  for (int s = 0; s < model.observations().num_samples(); ++s)
    w2.segment<3>(3 * s) = model.observations().weight(s).cwiseAbs2() * noise * noise;
  const Eigen::Matrix2d jtj_inv = (j.transpose() * j).inverse();
  const Eigen::Matrix2d cov = jtj_inv * j.transpose() * w2.asDiagonal() * j * jtj_inv;
  EXPECT_LT(std::abs(r.youngs_modulus - 2e5), 4 * std::sqrt(cov(0, 0)));
  EXPECT_LT(std::abs(r.poissons_ratio - 0.4), 4 * std::sqrt(cov(1, 1)));
  EXPECT_GT(std::sqrt(cov(0, 0)), 0.0);
  double sum = 0;
  for (int s = 0; s < model.observations().num_samples(); ++s)
    sum += model.residuals().segment<3>(3 * s).cwiseQuotient(model.observations().weight(s)).squaredNorm();
  const double rms = std::sqrt(sum / model.num_residuals());
  EXPECT_GT(rms, 0.8 * noise);
  EXPECT_LT(rms, 1.2 * noise);
}

}  // namespace
}  // namespace diffpd::solvers
