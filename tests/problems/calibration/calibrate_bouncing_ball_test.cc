// calibrate-bouncing-ball (problems/calibration/calibrate_bouncing_ball.h): the shipped
// captured motion is what its generator writes, and a fit through the impact
// (frictional contact, active sets held fixed in the Jacobian) recovers the
// true material from noise-free motion.
#include <gtest/gtest.h>

#include "calibration/calibrate_bouncing_ball.h"

namespace diffpd::problems {
namespace {

const std::string kDataDir = std::string(DIFFPD_SOURCE_DIR) + "/data/";

TEST(CalibrateBouncingBallTest, ShippedCapturedMotionIsWhatTheGeneratorWrites) {
  const BouncingBallCalibration ball;
  const CapturedMotion clean = ball.Synthesize(/*clean=*/true);
  const CapturedMotion shipped = ReadCapturedMotion(kDataDir + "bouncing_ball_motion_clean.csv");
  const CapturedMotion noisy = ReadCapturedMotion(kDataDir + "bouncing_ball_motion.csv");
  ASSERT_EQ(shipped.samples.size(), clean.samples.size());
  ASSERT_EQ(noisy.samples.size(), clean.samples.size());
  EXPECT_EQ(clean.markers.size(), 6u);
  double sum = 0;
  for (size_t s = 0; s < clean.samples.size(); ++s) {
    EXPECT_EQ(shipped.samples[s].marker, clean.samples[s].marker);
    EXPECT_LT((shipped.samples[s].position - clean.samples[s].position).norm(), 1e-9) << "sample " << s;
    sum += (noisy.samples[s].position - clean.samples[s].position).squaredNorm();
  }
  const double rms = std::sqrt(sum / (3.0 * clean.samples.size()));
  EXPECT_GT(rms, 0.7 * ball.noise());
  EXPECT_LT(rms, 1.3 * ball.noise());
}

// Starts 10% off the truth.
class NearbyBall : public BouncingBallCalibration {
 public:
  MaterialParameters initial_guess() const override { return MaterialParameters{4.5e5, 0.43, 1e3}; }
};

TEST(CalibrateBouncingBallTest, FitThroughTheImpactRecoversTheTrueMaterial) {
  // The frames up to 0.1 s: fall, impact (from about 0.07 s) and rebound start.
  CapturedMotion motion = ReadCapturedMotion(kDataDir + "bouncing_ball_motion_clean.csv");
  std::vector<MarkerSample> kept;
  for (const MarkerSample& s : motion.samples)
    if (s.time <= 0.1 + 1e-12) kept.push_back(s);
  motion.samples = kept;
  const NearbyBall ball;
  const CalibrationFit fit = ball.Fit(motion, Method::kNewtonCholesky, 8, nullptr);
  ASSERT_TRUE(fit.usable) << fit.termination;
  int contact_steps = 0;
  for (const StepReport& r : fit.rollout.reports) contact_steps += !r.contact_nodes.empty();
  EXPECT_GT(contact_steps, 5);
  EXPECT_NEAR(fit.values[0] / 5e5, 1.0, 1e-2);
  EXPECT_NEAR(fit.values[1] / 0.4, 1.0, 1e-2);
  EXPECT_LT(fit.final_cost, 1e-3 * fit.initial_cost);
}

}  // namespace
}  // namespace diffpd::problems
