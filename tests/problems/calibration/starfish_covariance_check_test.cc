// The Monte Carlo check of the starfish fit's standard deviations
// (starfish_covariance_check.h) on a small instance: a cantilever of 8 hex
// elements with one tendon-driven muscle along one side, two tip markers
// sampled every other step of 1/120 s for 0.4 s, the starfish's five fitted
// values (E, nu, tendon slack, lag, length). With noise small enough for the
// fit to be linear around the truth, the refitted values' spread over 30
// synthetic recordings matches the median standard deviation ceres::Covariance
// reports, within the sampling error of a standard deviation from 30 samples
// (about 13%, so [0.7, 1.4] is a band of about 2.5-3 sigma); the refits
// centre on the truth. Options out of range are refused with their messages.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "calibration/starfish_covariance_check.h"
#include "diffpd/box_mesh.h"
#include "diffpd/error.h"
#include "diffpd/solvers/core/marker_residuals.h"
#include "diffpd/solvers/core/material_block.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

constexpr double kTimeStep = 1.0 / 120;
constexpr int kSteps = 48;

Scene BeamScene() {
  Scene scene;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(2, 1, 4), Vec3(0.01, 0.005, 0.06));
  scene.material = MaterialParameters{2e5, 0.35, 400};
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  std::vector<int> base;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) < 1e-9) base.push_back(i);
  FixNodes(&scene, base);
  Muscle muscle;
  muscle.stiffness = 2e6;
  muscle.fibers = {Vec3(0, 0, 1)};
  for (int e = 0; e < scene.mesh.num_elements(); ++e) {
    double x = 0;
    for (int a = 0; a < scene.mesh.elements.rows(); ++a) x += scene.mesh.vertices(0, scene.mesh.elements(a, e));
    if (x / scene.mesh.elements.rows() < 0.005) muscle.elements.push_back(e);
  }
  scene.muscles = {muscle};
  return scene;
}

// A tendon that pulls to 12 mm, releases to 4 mm, pulls again (m per step).
std::vector<double> Contraction() {
  std::vector<double> c(kSteps);
  for (int k = 0; k < kSteps; ++k) c[k] = k < 4 ? 0.0 : k < 20 ? 0.012 : k < 32 ? 0.004 : 0.010;
  return c;
}

// Two tip markers, every other step, weight 1/mm on each axis.
CapturedMotion Layout(const Scene& scene) {
  CapturedMotion motion;
  int tips[2] = {-1, -1};
  for (int i = 0; i < scene.mesh.num_vertices(); ++i) {
    const Vec3 p = scene.mesh.vertices.col(i);
    if (p(2) < 0.06 - 1e-9 || p(1) > 1e-9) continue;
    if (p(0) < 1e-9) tips[0] = i;
    if (p(0) > 0.01 - 1e-9) tips[1] = i;
  }
  for (int m = 0; m < 2; ++m) motion.markers.push_back(Marker{m, tips[m], -1, Vec3::Zero(), 0});
  for (int k = 2; k <= kSteps; k += 2)
    for (int m = 0; m < 2; ++m) {
      MarkerSample s;
      s.time = k * kTimeStep;
      s.marker = m;
      s.position = scene.mesh.vertices.col(tips[m]);
      s.weight = Vec3::Constant(1e3);
      motion.samples.push_back(s);
    }
  return motion;
}

std::unique_ptr<solvers::RolloutFunction> Model(const CapturedMotion& motion) {
  const Scene scene = BeamScene();
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.time_step = kTimeStep;
  options.rel_tolerance = 1e-8;
  options.abs_tolerance = 1e-12;
  options.num_threads = 1;
  auto model = std::make_unique<solvers::RolloutFunction>(scene, options, kSteps);
  std::vector<StepInput> inputs(kSteps);
  for (StepInput& in : inputs) in.activation = VectorXd::Ones(1);
  model->SetInputs(std::move(inputs));
  model->AddBlock(std::make_unique<solvers::MaterialBlock>(
      std::vector<solvers::MaterialBlock::Entry>{solvers::MaterialField::kYoungsModulus,
                                                 solvers::MaterialField::kPoissonsRatio},
      scene));
  model->AddBlock(std::make_unique<TendonActuationBlock>(Contraction(), kTimeStep, 1, StarfishActuation{}));
  model->AddFunctional(std::make_unique<solvers::MarkerResiduals>(motion, scene.mesh, kTimeStep, kSteps));
  return model;
}

TEST(StarfishCovarianceCheckTest, RefittedSpreadMatchesTheReportedStandardDeviations) {
  const Scene scene = BeamScene();
  ASSERT_FALSE(scene.muscles[0].elements.empty());
  const CapturedMotion layout = Layout(scene);
  ASSERT_GE(layout.markers[0].vertex, 0);
  ASSERT_GE(layout.markers[1].vertex, 0);
  const StarfishTruth truth{MaterialParameters{2e5, 0.35, 400}, StarfishActuation{0.002, 0.04, 0.06}, std::nullopt};
  StarfishCovarianceCheckOptions options;
  options.refits = 30;
  options.noise = 0.02;  // 0.02 mm on every coordinate (weights 1/mm)
  options.seed = 7;
  const StarfishCovarianceCheck check = CheckStarfishCovariance(Model, layout, truth, options);
  EXPECT_EQ(check.refits, 30);
  EXPECT_EQ(check.usable, 30);
  ASSERT_EQ(check.names.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    const double ratio = check.empirical_sd[i] / check.reported_sd[i];
    std::printf("%-15s truth %-10.4g mean %-10.4g spread %-10.4g reported %-10.4g ratio %.3f\n", check.names[i].c_str(),
                check.truth[i], check.mean[i], check.empirical_sd[i], check.reported_sd[i], ratio);
    EXPECT_GT(ratio, 0.7) << check.names[i] << ": spread " << check.empirical_sd[i] << ", reported "
                          << check.reported_sd[i];
    EXPECT_LT(ratio, 1.4) << check.names[i] << ": spread " << check.empirical_sd[i] << ", reported "
                          << check.reported_sd[i];
    // The mean of 30 refits lies within 4 standard errors of the truth.
    EXPECT_LT(std::abs(check.mean[i] - check.truth[i]), 4 * check.empirical_sd[i] / std::sqrt(30.0)) << check.names[i];
    EXPECT_GT(check.reported_sd[i], 0) << check.names[i];
  }
}

TEST(StarfishCovarianceCheckTest, RefusesOptionsOutOfRange) {
  const Scene scene = BeamScene();
  const StarfishTruth truth{MaterialParameters{2e5, 0.35, 400}, StarfishActuation{0.002, 0.04, 0.06}, std::nullopt};
  StarfishCovarianceCheckOptions options;
  options.refits = 1;
  EXPECT_THROW_MESSAGE(CheckStarfishCovariance(Model, Layout(scene), truth, options), InvalidInputError,
                       "refits = 1 is invalid: must be >= 2");
  options.refits = 2;
  options.noise = 0;
  EXPECT_THROW_MESSAGE(CheckStarfishCovariance(Model, Layout(scene), truth, options), InvalidInputError,
                       "noise = 0 is invalid: must be finite and > 0");
}

}  // namespace
}  // namespace diffpd::problems
