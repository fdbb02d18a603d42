// calibrate-cantilever (problems/calibration/calibrate_cantilever.h), the
// default job of ./run.sh: the shipped captured motion is what its generator
// writes, a fit of the shipped (noisy) motion from the default start recovers
// the true material, and a run writes its report, trajectory and plot data.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "calibration/calibrate_cantilever.h"
#include "cli/commands.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

const std::string kDataDir = std::string(DIFFPD_SOURCE_DIR) + "/data/";

TEST(CalibrateCantileverTest, ShippedCapturedMotionIsWhatTheGeneratorWrites) {
  const CantileverCalibration beam;
  const CapturedMotion clean = beam.Synthesize(/*clean=*/true);
  const CapturedMotion shipped = ReadCapturedMotion(kDataDir + "cantilever_motion_clean.csv");
  const CapturedMotion noisy = ReadCapturedMotion(kDataDir + "cantilever_motion.csv");
  EXPECT_EQ(beam.default_steps(), 80);
  EXPECT_EQ(clean.markers.size(), 6u);
  EXPECT_EQ(clean.samples.size(), 72u);  // 12 frames at 30 Hz
  ASSERT_EQ(shipped.samples.size(), clean.samples.size());
  ASSERT_EQ(noisy.samples.size(), clean.samples.size());
  double sum = 0;
  for (size_t s = 0; s < clean.samples.size(); ++s) {
    EXPECT_EQ(shipped.samples[s].marker, clean.samples[s].marker);
    EXPECT_LT((shipped.samples[s].position - clean.samples[s].position).norm(), 1e-9) << "sample " << s;
    sum += (noisy.samples[s].position - clean.samples[s].position).squaredNorm();
  }
  // The noisy file is the clean motion plus the documented noise.
  const double rms = std::sqrt(sum / (3.0 * clean.samples.size()));
  EXPECT_GT(rms, 0.7 * beam.noise());
  EXPECT_LT(rms, 1.3 * beam.noise());
}

// The main job's fit: the shipped noisy motion, the problem's own start
// (E 2.5x too low, nu 0.45 against 0.35) and default method (pd-lbfgs). With
// 0.1 mm noise on motions of tens of millimetres both parameters come back
// within a fraction of a percent; the bounds leave room for the noise only.
TEST(CalibrateCantileverTest, FitOfTheShippedMotionRecoversTheTrueMaterial) {
  const CantileverCalibration beam;
  const CalibrationFit fit = beam.Fit(ReadCapturedMotion(kDataDir + "cantilever_motion.csv"),
                                      beam.default_methods().front(), beam.max_iterations(), nullptr);
  ASSERT_TRUE(fit.usable) << fit.termination;
  EXPECT_EQ(fit.method, Method::kPdLbfgs);
  EXPECT_NEAR(fit.values[0] / 5e5, 1.0, 5e-3);
  EXPECT_NEAR(fit.values[1] / 0.35, 1.0, 1e-2);
  // What is left is the noise: 0.1 mm per coordinate, sqrt(3) x 0.1 mm per marker.
  EXPECT_LT(fit.marker_rmse_m, 2.5e-4);
  EXPECT_LT(fit.final_cost, 1e-3 * fit.initial_cost);
  EXPECT_EQ(fit.rollout.num_steps(), 80);
}

TEST(CalibrateCantileverTest, RunWritesTheReportTrajectoryAndMarkerFiles) {
  const CantileverCalibration beam;
  const testing::TemporaryDirectory dir("diffpd-calibrate-cantilever");
  const std::filesystem::path& out = dir.path();
  CommandArgs args;
  args.problem = beam.name();
  args.methods = {"pd-lbfgs"};  // the default data: data/cantilever_motion.csv
  args.max_iterations = 1;
  args.json = true;
  args.out_dir = out.string();
  ::testing::internal::CaptureStdout();
  const int code = beam.Run(args);
  const std::string stdout_text = ::testing::internal::GetCapturedStdout();
  ASSERT_EQ(code, 0) << stdout_text;
  const nlohmann::json report = nlohmann::json::parse(stdout_text);  // stdout is exactly one JSON document
  EXPECT_EQ(report["truth"]["youngs_modulus"].get<double>(), 5e5);
  EXPECT_EQ(report["truth"]["poissons_ratio"].get<double>(), 0.35);
  EXPECT_NE(report["data_file"].get<std::string>().find("cantilever_motion.csv"), std::string::npos);
  ASSERT_EQ(report["fits"].size(), 1u);
  EXPECT_EQ(report["fits"][0]["iterations"], 1);
  EXPECT_TRUE(std::filesystem::exists(out / "calibrate-cantilever_fitted.pvd"));
  EXPECT_TRUE(std::filesystem::exists(out / "markers.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "calibration.json"));
}

}  // namespace
}  // namespace diffpd::problems
