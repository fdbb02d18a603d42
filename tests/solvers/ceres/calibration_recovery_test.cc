// Synthetic recovery of known material parameters with Ceres over the rollout
// core (marker residual blocks, the evaluation callback, coordinate
// manifolds): exact recovery from noise-free motion with PD and
// Newton-Cholesky, of a base and a region material, and errors within the
// linearised spread of the noise with noisy motion.
#include <gtest/gtest.h>

#include <ceres/ceres.h>

#include "solvers/ceres/calibration_fixture.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

TEST(CalibrationRecoveryTest, RecoversTrueMaterialFromNoiseFreeMotionWithPdAndNewton) {
  for (auto [method, tets] : {std::pair{Method::kNewtonCholesky, false}, std::pair{Method::kPd, true}}) {
    auto f = Synthetic(method, tets, MaterialParameters{1e5, 0.3, 1e3}).MakeFunction(YoungsModulusAndPoissonsRatio());
    ceres::Solver::Summary summary;
    const std::vector<double> material = FitMaterialBlock(f.get(), &summary);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
    EXPECT_NEAR(material[0] / 2e5, 1.0, 1e-6) << ToString(method) << "\n" << summary.FullReport();
    EXPECT_NEAR(material[1] / 0.4, 1.0, 1e-6) << ToString(method);
    EXPECT_LT(summary.final_cost, 1e-12);
  }
}

TEST(CalibrationRecoveryTest, NoisyMotionGivesErrorsWithinTheNoisesLinearisedSpread) {
  // 0.05 mm of Gaussian noise: the fitted material lies within 4 standard
  // deviations of the truth, the deviations from the Gauss-Newton covariance
  // at the solution, Cov = (J^T J)^-1 J^T diag(w^2 sigma^2) J (J^T J)^-1,
  // and the unweighted marker RMS error matches the noise.
  const double noise = 5e-5;
  auto f = Synthetic(Method::kNewtonCholesky, false, MaterialParameters{1e5, 0.3, 1e3}, 8, noise)
               .MakeFunction(YoungsModulusAndPoissonsRatio());
  ceres::Solver::Summary summary;
  const std::vector<double> fitted = FitMaterialBlock(f.get(), &summary);
  ASSERT_TRUE(summary.IsSolutionUsable());
  VectorXd r;
  MatrixXd j;
  ASSERT_TRUE(f->Evaluate(Eigen::Vector2d(fitted[0], fitted[1]), f->RowsOf(0), &r, &j));
  const MarkerObservations& obs = dynamic_cast<const MarkerResiduals&>(f->functional(0)).observations();
  VectorXd w2(j.rows());
  for (int s = 0; s < obs.num_samples(); ++s) w2.segment<3>(3 * s) = obs.weight(s).cwiseAbs2() * noise * noise;
  const Eigen::Matrix2d jtj_inv = (j.transpose() * j).inverse();
  const Eigen::Matrix2d cov = jtj_inv * j.transpose() * w2.asDiagonal() * j * jtj_inv;
  EXPECT_LT(std::abs(fitted[0] - 2e5), 4 * std::sqrt(cov(0, 0)));
  EXPECT_LT(std::abs(fitted[1] - 0.4), 4 * std::sqrt(cov(1, 1)));
  EXPECT_GT(std::sqrt(cov(0, 0)), 0.0);
  double sum = 0;
  for (int s = 0; s < obs.num_samples(); ++s) sum += r.segment<3>(3 * s).cwiseQuotient(obs.weight(s)).squaredNorm();
  const double rms = std::sqrt(sum / r.size());
  EXPECT_GT(rms, 0.8 * noise);
  EXPECT_LT(rms, 1.2 * noise);
}

// A cantilever whose clamped half is stiff (base material, E = 2e5 Pa) and
// whose free half is 5x softer (region 0): both moduli and Poisson's ratios
// recovered from noise-free markers, starting 50% / 0.1 off.
TEST(CalibrationRecoveryTest, RecoversAStiffAndASoftHalfFromNoiseFreeMarkers) {
  Scene truth = SmallBeamScene();
  truth.material = MaterialParameters{2e5, 0.4, 1e3};
  MaterialRegion soft;
  soft.elements = ElementsWithCentroidX(truth.mesh, 0.08, 1.0);
  soft.material = MaterialParameters{4e4, 0.3, 1e3};
  truth.material_regions = {soft};
  SyntheticCalibration c = SyntheticFromScene(truth, Method::kNewtonCholesky, 8);
  c.scene.material = MaterialParameters{1e5, 0.3, 1e3};
  c.scene.material_regions[0].material = MaterialParameters{1e5, 0.4, 1e3};
  auto f = c.MakeFunction({MaterialField::kYoungsModulus,
                           MaterialField::kPoissonsRatio,
                           {MaterialField::kYoungsModulus, 0},
                           {MaterialField::kPoissonsRatio, 0}});
  ceres::Solver::Summary summary;
  const std::vector<double> material = FitMaterialBlock(f.get(), &summary);
  ASSERT_TRUE(summary.IsSolutionUsable()) << summary.FullReport();
  EXPECT_NEAR(material[0] / 2e5, 1.0, 1e-5) << summary.FullReport();
  EXPECT_NEAR(material[1] / 0.4, 1.0, 1e-5);
  EXPECT_NEAR(material[2] / 4e4, 1.0, 1e-5);
  EXPECT_NEAR(material[3] / 0.3, 1.0, 1e-5);
  EXPECT_LT(summary.final_cost, 1e-10);
}

}  // namespace
}  // namespace diffpd::testing
