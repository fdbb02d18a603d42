// calibrate-plant (problems/calibration/calibrate_plant.h): the shipped captured motion
// is what its generator writes, and a run on the noise-free file recovers
// the true material within 1% and writes its report and files.
#include <gtest/gtest.h>

#include <filesystem>

#include <nlohmann/json.hpp>

#include "calibration/calibrate_plant.h"
#include "cli/commands.h"
#include "diffpd/error.h"
#include "util/expect_message.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

const std::string kDataDir = std::string(DIFFPD_SOURCE_DIR) + "/data/";

void ExpectSameMotion(const CapturedMotion& a, const CapturedMotion& b) {
  ASSERT_EQ(a.markers.size(), b.markers.size());
  for (size_t m = 0; m < a.markers.size(); ++m) {
    EXPECT_EQ(a.markers[m].id, b.markers[m].id);
    EXPECT_EQ(a.markers[m].vertex, b.markers[m].vertex);
  }
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (size_t s = 0; s < a.samples.size(); ++s) {
    EXPECT_EQ(a.samples[s].marker, b.samples[s].marker);
    EXPECT_NEAR(a.samples[s].time, b.samples[s].time, 1e-15);
    EXPECT_LT((a.samples[s].position - b.samples[s].position).norm(), 1e-9) << "sample " << s;
  }
}

TEST(CalibratePlantTest, ShippedCapturedMotionIsWhatTheGeneratorWrites) {
  const PlantCalibration plant;
  const CapturedMotion clean = plant.Synthesize(/*clean=*/true);
  ExpectSameMotion(ReadCapturedMotion(kDataDir + "plant_motion_clean.csv"), clean);
  const CapturedMotion noisy = ReadCapturedMotion(kDataDir + "plant_motion.csv");
  // The noisy file is the clean motion plus the documented noise.
  ASSERT_EQ(noisy.samples.size(), clean.samples.size());
  double sum = 0;
  for (size_t s = 0; s < clean.samples.size(); ++s)
    sum += (noisy.samples[s].position - clean.samples[s].position).squaredNorm();
  const double rms = std::sqrt(sum / (3.0 * clean.samples.size()));
  EXPECT_GT(rms, 0.7 * plant.noise());
  EXPECT_LT(rms, 1.3 * plant.noise());
  EXPECT_EQ(plant.default_steps(), 30);
  EXPECT_EQ(clean.markers.size(), 5u);
  EXPECT_EQ(clean.samples.size(), 45u);  // 9 frames at 30 Hz
}

// The plant with a starting guess 10% off, so that the test fits quickly.
class NearbyPlant : public PlantCalibration {
 public:
  MaterialParameters initial_guess() const override { return MaterialParameters{2.7e5, 0.33, 1e3}; }
};

TEST(CalibratePlantTest, FitOfNoiseFreeMotionRecoversTheTrueMaterial) {
  const NearbyPlant plant;
  const CalibrationFit fit =
      plant.Fit(ReadCapturedMotion(kDataDir + "plant_motion_clean.csv"), Method::kNewtonCholesky, 10, nullptr);
  ASSERT_TRUE(fit.usable) << fit.termination;
  EXPECT_NEAR(fit.values[0] / 3e5, 1.0, 1e-3);
  EXPECT_NEAR(fit.values[1] / 0.3, 1.0, 1e-3);
  EXPECT_LT(fit.marker_rmse_m, 1e-6);
  EXPECT_LT(fit.final_cost, 1e-3 * fit.initial_cost);
  EXPECT_EQ(fit.rollout.num_steps(), 30);
  EXPECT_GT(fit.statistics.forward_seconds, 0.0);
}

// Runs the problem with `args` and expects InvalidInputError with `message`.
void ExpectRefused(const PlantCalibration& problem, const CommandArgs& args, const std::string& message) {
  EXPECT_THROW_MESSAGE(problem.Run(args), InvalidInputError, message);
}

// The simulator-tuning and verbosity flags of `run` are refused, not silently ignored.
TEST(CalibratePlantTest, SimulatorTuningFlagsAreRefusedWithAMessage) {
  const PlantCalibration problem;
  const std::string tuning =
      "--lbfgs-scale and --no-rigid-correction are not used by the calibration problem 'calibrate-plant' (it fits "
      "with the library's default solver settings)";
  CommandArgs scaled, uncorrected, verbose;
  scaled.lbfgs_weight_scale = 0.5;
  uncorrected.rigid_mode_correction = false;
  verbose.verbosity = 1;
  ExpectRefused(problem, scaled, tuning);
  ExpectRefused(problem, uncorrected, tuning);
  ExpectRefused(problem, verbose,
                "--verbosity is not used by the calibration problem 'calibrate-plant' (its log is Ceres' iteration "
                "table; the simulator stays silent)");
}

TEST(CalibratePlantTest, RunWritesTheJsonReportAndItsFiles) {
  const NearbyPlant plant;
  const testing::TemporaryDirectory temp("diffpd-calibrate-plant");
  const std::filesystem::path out = temp.path();
  CommandArgs args;
  args.problem = plant.name();
  args.methods = {"newton-cholesky"};  // the default data: data/plant_motion.csv
  args.max_iterations = 1;
  args.json = true;
  args.out_dir = out.string();
  ::testing::internal::CaptureStdout();
  const int code = plant.Run(args);
  const std::string stdout_text = ::testing::internal::GetCapturedStdout();
  ASSERT_EQ(code, 0) << stdout_text;
  const nlohmann::json report = nlohmann::json::parse(stdout_text);  // stdout is exactly one JSON document
  EXPECT_TRUE(report["youngs_modulus"].is_number()) << report.dump(2);
  EXPECT_TRUE(report["poissons_ratio"].is_number());
  EXPECT_EQ(report["truth"]["youngs_modulus"].get<double>(), 3e5);
  EXPECT_EQ(report["truth"]["poissons_ratio"].get<double>(), 0.3);
  EXPECT_GT(report["evaluations"].get<int>(), 0);
  EXPECT_GT(report["forward_seconds"].get<double>(), 0.0);
  EXPECT_GT(report["backward_seconds"].get<double>(), 0.0);
  EXPECT_TRUE(report["final_cost"].is_number());
  EXPECT_NE(report["data_file"].get<std::string>().find("plant_motion.csv"), std::string::npos);
  ASSERT_EQ(report["fits"].size(), 1u);
  EXPECT_EQ(report["fits"][0]["method"], "newton-cholesky");
  EXPECT_EQ(report["fits"][0]["iterations"], 1);
  EXPECT_TRUE(std::filesystem::exists(out / "calibrate-plant_fitted.pvd"));
  EXPECT_TRUE(std::filesystem::exists(out / "markers.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "marker_paths.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "calibration.json"));
}

}  // namespace
}  // namespace diffpd::problems
