// Plant recordings (problems/calibration/plant_recordings.h): the gusts turn
// about the vertical axis at equal speed, recording 0 is calibrate-plant's
// own synthetic motion, every recording's term starts from calibrate-plant's
// guess with the marker residuals as rows, and bad indices are named.
#include <gtest/gtest.h>

#include <cmath>

#include "calibration/calibrate_plant.h"
#include "calibration/plant_recordings.h"
#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

TEST(PlantRecordingsTest, GustsTurnAboutTheVerticalAtEqualSpeed) {
  const Vec3 first = PlantGust(0, 4);
  EXPECT_EQ(first, Vec3(0.3, 0.15, 0));
  for (int i = 1; i < 4; ++i) {
    const Vec3 g = PlantGust(i, 4);
    EXPECT_NEAR(g.norm(), first.norm(), 1e-15);
    EXPECT_EQ(g.z(), 0.0);
    EXPECT_NEAR(std::atan2(first.cross(g).z(), first.dot(g)), std::remainder(M_PI / 2 * i, 2 * M_PI), 1e-12)
        << "recording " << i;
  }
}

TEST(PlantRecordingsTest, RecordingZeroIsThePlantProblemsMotionAndTermsStartFromItsGuess) {
  const PlantCalibration plant;
  const CapturedMotion own = plant.Synthesize(/*clean=*/false);
  const CapturedMotion first = SynthesizePlantRecording(0, 3);
  ASSERT_EQ(first.samples.size(), own.samples.size());
  for (size_t s = 0; s < own.samples.size(); ++s)
    EXPECT_EQ(first.samples[s].position, own.samples[s].position) << "sample " << s;
  const solvers::RolloutTerm term = PlantRecordingTerm(1, PlantRecordingsOptions{3, Method::kPdLbfgs, 1});
  EXPECT_EQ(term.rows.size(), 3 * own.samples.size());
  const VectorXd start = term.function->initial_parameters();
  EXPECT_EQ(start(0), plant.initial_guess().youngs_modulus);
  EXPECT_EQ(start(1), plant.initial_guess().poissons_ratio);
}

TEST(PlantRecordingsTest, IndicesOutOfRangeAreNamed) {
  EXPECT_THROW_MESSAGE(PlantGust(4, 4), InvalidInputError, "plant recording 4 is out of range [0, 4)");
  EXPECT_THROW_MESSAGE(PlantGust(0, 0), InvalidInputError, "plant recordings: count = 0 is invalid: must be >= 1");
}

}  // namespace
}  // namespace diffpd::problems
