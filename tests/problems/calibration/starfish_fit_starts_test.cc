// The starting points of the starfish fit (problems/calibration/
// starfish_fit_starts.h): the first is the given start, every other lies
// inside the fit's intervals and drives both recordings without a negative
// activation, a count outside [1, 4] is refused with its message, the choice
// among fits takes the lowest usable cost, and a fit from another start
// starts at that start's water.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>

#include "calibration/calibrate_starfish.h"
#include "calibration/starfish_fit_starts.h"
#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

const std::string kStarfishDir = std::string(DIFFPD_SHARED_DIR) + "/data/starfish/";

StarfishStart DefaultStart() {
  StarfishStart s{MaterialParameters{5e5, 0.4, 400}, StarfishCalibration::ActuationGuess(),
                  StarfishCalibration::WaterGuess()};
  s.actuation.release_lag = s.actuation.lag;
  return s;
}

TEST(StarfishFitStartsTest, FirstIsTheGivenStartOthersLieInsideTheFitsIntervals) {
  const StarfishStart first = DefaultStart();
  const std::vector<StarfishStart> starts = StarfishStarts(kMaxStarfishStarts, first);
  ASSERT_EQ(starts.size(), 4u);
  EXPECT_EQ(starts[0].material.youngs_modulus, first.material.youngs_modulus);
  EXPECT_EQ(starts[0].material.poissons_ratio, first.material.poissons_ratio);
  EXPECT_EQ(starts[0].actuation.slack, first.actuation.slack);
  EXPECT_EQ(starts[0].actuation.lag, first.actuation.lag);
  EXPECT_EQ(starts[0].actuation.length, first.actuation.length);
  EXPECT_EQ(starts[0].actuation.release_lag, first.actuation.release_lag);
  EXPECT_EQ(starts[0].water.drag_normal, first.water.drag_normal);
  std::set<double> youngs, lengths, drags;
  for (const StarfishStart& s : starts) {
    EXPECT_NO_THROW(StarfishFitStart(s.material, s.actuation, false));
    EXPECT_NO_THROW(CheckStarfishWaterStart(s.water));
    ASSERT_TRUE(s.actuation.release_lag.has_value());
    EXPECT_GT(*s.actuation.release_lag, 0.001);
    EXPECT_LT(*s.actuation.release_lag, 0.5);
    EXPECT_EQ(s.material.density, first.material.density);
    youngs.insert(s.material.youngs_modulus);
    lengths.insert(s.actuation.length);
    drags.insert(s.water.drag_normal);
  }
  EXPECT_EQ(youngs.size(), 4u);  // the starts differ in what the data do not pin down
  EXPECT_EQ(lengths.size(), 4u);
  EXPECT_EQ(drags.size(), 4u);
  EXPECT_EQ(StarfishStarts(1, first).size(), 1u);
  StarfishStart symmetric = first;
  symmetric.actuation.release_lag.reset();
  for (const StarfishStart& s : StarfishStarts(3, symmetric)) EXPECT_FALSE(s.actuation.release_lag.has_value());
  EXPECT_THROW_MESSAGE(StarfishStarts(0, first), InvalidInputError,
                       "starfish starts: count = 0 is invalid: must be in [1, 4]");
  EXPECT_THROW_MESSAGE(StarfishStarts(5, first), InvalidInputError,
                       "starfish starts: count = 5 is invalid: must be in [1, 4]");
}

// Every start's tendon (slack + length) is longer than the recordings' largest
// contraction: its activations over the first 10 s of both files are >= 0.
TEST(StarfishFitStartsTest, EveryStartDrivesBothRecordingsWithoutANegativeActivation) {
  const StarfishCalibration starfish;
  for (const char* file : {"data_horizontal_cyclic1.csv", "data_horizontal_cyclic2.csv"}) {
    const StarfishRecording recording = ReadStarfishRecording(kStarfishDir + file);
    const StarfishWindow window = MakeStarfishWindow(recording, 0, 10);
    const std::vector<double> contraction = starfish.WindowContractions(recording, window);
    const double h = StarfishTimeStep(recording, window, starfish.substeps());
    for (const StarfishStart& s : StarfishStarts(kMaxStarfishStarts, DefaultStart())) {
      int negative = -2;
      const std::vector<double> a = StarfishActivationsUntilNegative(contraction, h, s.actuation, nullptr, &negative);
      EXPECT_EQ(negative, -1) << file << ", start with length " << s.actuation.length;
      EXPECT_EQ(a.size(), contraction.size());
    }
  }
}

TEST(StarfishFitStartsTest, BestFitIsTheUsableOneWithTheLowestCost) {
  auto fit = [](double cost, bool usable) {
    StarfishFit f;
    f.final_cost = cost;
    f.usable = usable;
    return f;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(BestStarfishFit({fit(2.0, true), fit(1.0, false), fit(1.5, true), fit(nan, true)}), 2);
  EXPECT_EQ(BestStarfishFit({fit(0.7, true), fit(0.7, true)}), 0);
  EXPECT_EQ(BestStarfishFit({fit(nan, true), fit(0.9, true)}), 1);
  EXPECT_EQ(BestStarfishFit({fit(1.0, false)}), -1);
  EXPECT_EQ(BestStarfishFit({}), -1);
}

// A fit from another start starts at its water: its initial cost is the
// model's at that start, not at the default water's; a water outside the
// fit's intervals is refused.
TEST(StarfishFitStartsTest, FitStartsAtTheGivenWater) {
  StarfishCalibration starfish;
  starfish.set_substeps(1);
  starfish.set_fit_release_lag(false);
  starfish.set_fit_density(false);  // 8 values: E, nu, slack, lag, length and the water's three
  const StarfishRecording recording = ReadStarfishRecording(kStarfishDir + "data_horizontal_cyclic1.csv");
  const StarfishWindow window = MakeStarfishWindow(recording, 1.15, 0.15);
  const SolverOptions options = starfish.Options(Method::kPdLbfgs, 1);
  const StarfishStart start = StarfishStarts(2, DefaultStart())[1];
  const StarfishFit fit =
      starfish.Fit(recording, window, options, start.material, start.actuation, 1, nullptr, start.water);
  EXPECT_TRUE(fit.usable) << fit.termination;
  StarfishActuation symmetric = start.actuation;  // the model of a symmetric servo has no release lag
  symmetric.release_lag.reset();
  auto model = starfish.MakeModel(recording, window, options, start.material, symmetric, start.water);
  VectorXd p(8), r;
  p << start.material.youngs_modulus, start.material.poissons_ratio, start.actuation.slack, start.actuation.lag,
      start.actuation.length, start.water.drag_tangential, start.water.drag_normal, start.water.thrust;
  ASSERT_TRUE(model->Evaluate(p, model->AllRows(), &r, nullptr)) << model->statistics().last_error;
  EXPECT_NEAR(fit.initial_cost, 0.5 * r.squaredNorm(), 1e-9 * fit.initial_cost);
  auto default_water =
      starfish.MakeModel(recording, window, options, start.material, symmetric, StarfishCalibration::WaterGuess());
  VectorXd q = p, rd;
  q.tail(3) << 0.05, 2.05, 0.1;
  ASSERT_TRUE(default_water->Evaluate(q, default_water->AllRows(), &rd, nullptr));
  EXPECT_GT(std::abs(0.5 * rd.squaredNorm() - fit.initial_cost), 1e-6 * fit.initial_cost)
      << "the water changes the cost here";
  EXPECT_THROW_MESSAGE(starfish.Fit(recording, window, options, start.material, start.actuation, 1, nullptr,
                                    StarfishWater{0.05, 30, 0.1}),
                       InvalidInputError, "drag_normal = 30 is outside the fit's interval (0.2, 20)");
}

}  // namespace
}  // namespace diffpd::problems
