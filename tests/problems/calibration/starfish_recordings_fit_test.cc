// The starfish fit over several recordings (starfish_recordings_fit.h) on
// short windows (0.15 s from 1.15 s, one step per frame): over one recording
// it fits as the single-recording fit does; over cyclic1 and cyclic2 its
// cost is the sum of the recordings' costs, it drops, and the per-recording
// costs add up; a problem set up otherwise and a start outside the bounds are
// refused with their messages.
#include <gtest/gtest.h>

#include "calibration/starfish_recordings_fit.h"
#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

const std::string kStarfishDir = std::string(DIFFPD_SHARED_DIR) + "/data/starfish/";
const std::string kCyclic1 = kStarfishDir + "data_horizontal_cyclic1.csv";
const std::string kCyclic2 = kStarfishDir + "data_horizontal_cyclic2.csv";

class StarfishRecordingsFitTest : public ::testing::Test {
 protected:
  StarfishRecordingsFitTest() {
    starfish_.set_substeps(1);
    recordings_.start = 1.15;
    recordings_.seconds = 0.15;
  }
  SolverOptions Options() const {
    SolverOptions o = starfish_.Options(Method::kPdLbfgs, 1);
    o.adjoint_solver = AdjointSolver::kDirect;
    return o;
  }
  solvers::LocalRolloutSet Set(const std::vector<std::string>& paths) const {
    std::vector<solvers::RolloutTerm> terms;
    for (const std::string& path : paths)
      terms.push_back(StarfishRecordingTerm(starfish_, path, Options(), recordings_));
    return solvers::LocalRolloutSet(std::move(terms), solvers::TermObjective::kLeastSquares);
  }
  StarfishCalibration starfish_;
  StarfishRecordingsOptions recordings_;
};

TEST_F(StarfishRecordingsFitTest, OneRecordingFitsAsTheSingleRecordingFit) {
  solvers::LocalRolloutSet set = Set({kCyclic1});
  const StarfishRecordingsFit over_set = FitStarfishOverSet(&set, 400, 3, nullptr);
  const StarfishRecording recording = ReadStarfishRecording(kCyclic1);
  // The set fits the 5 parameters: the scene's water and density, a symmetric servo.
  starfish_.set_fit_water(false);
  starfish_.set_fit_release_lag(false);
  starfish_.set_fit_density(false);
  const StarfishFit single =
      starfish_.Fit(recording, MakeStarfishWindow(recording, recordings_.start, recordings_.seconds), Options(),
                    recordings_.guess, recordings_.actuation_guess, 3, nullptr);
  ASSERT_TRUE(over_set.fit.usable) << over_set.fit.termination;
  EXPECT_NEAR(over_set.fit.initial_cost, single.initial_cost, 1e-12 * single.initial_cost);
  EXPECT_EQ(over_set.fit.iterations, single.iterations);
  // One residual block against one per frame: the same steps to rounding.
  EXPECT_NEAR(over_set.fit.final_cost, single.final_cost, 1e-6 * single.final_cost);
  EXPECT_NEAR(over_set.fit.material.youngs_modulus, single.material.youngs_modulus,
              1e-6 * single.material.youngs_modulus);
  EXPECT_NEAR(over_set.fit.material.poissons_ratio, single.material.poissons_ratio, 1e-6);
  EXPECT_NEAR(over_set.fit.actuation.slack, single.actuation.slack, 1e-6 * single.actuation.slack);
  EXPECT_NEAR(over_set.fit.actuation.lag, single.actuation.lag, 1e-6 * single.actuation.lag);
  EXPECT_NEAR(over_set.fit.actuation.length, single.actuation.length, 1e-6 * single.actuation.length);
  EXPECT_EQ(over_set.fit.material.density, 400);
}

TEST_F(StarfishRecordingsFitTest, TwoRecordingsCostTheSumOfTheirCostsAndTheFitLowersIt) {
  solvers::LocalRolloutSet both = Set({kCyclic1, kCyclic2});
  solvers::LocalRolloutSet first = Set({kCyclic1}), second = Set({kCyclic2});
  double l = 0, l1 = 0, l2 = 0;
  const VectorXd p = both.initial_parameters();
  ASSERT_TRUE(both.Value(p, &l)) << both.last_error();
  ASSERT_TRUE(first.Value(p, &l1));
  ASSERT_TRUE(second.Value(p, &l2));
  EXPECT_GT(l1, 0);
  EXPECT_GT(l2, 0);
  EXPECT_NEAR(l, l1 + l2, 1e-14 * l);
  const StarfishRecordingsFit r = FitStarfishOverSet(&both, 400, 2, nullptr);
  ASSERT_TRUE(r.fit.usable) << r.fit.termination;
  EXPECT_NEAR(r.fit.initial_cost, l, 1e-12 * l);
  EXPECT_LT(r.fit.final_cost, r.fit.initial_cost);
  ASSERT_EQ(r.initial_costs.size(), 2u);
  ASSERT_EQ(r.final_costs.size(), 2u);
  EXPECT_NEAR(r.initial_costs[0], l1, 1e-14 * l1);
  EXPECT_NEAR(r.initial_costs[1], l2, 1e-14 * l2);
  EXPECT_NEAR(r.final_costs[0] + r.final_costs[1], r.fit.final_cost, 1e-12 * r.fit.final_cost);
  EXPECT_GE(r.evaluations, r.fit.iterations);
  EXPECT_EQ(r.fit.statistics.failures, 0) << r.fit.statistics.last_error;
}

TEST_F(StarfishRecordingsFitTest, RefusesOtherFitSettingsAndStartsOutsideTheBounds) {
  StarfishCalibration lbfgs;
  lbfgs.set_fit_method(StarfishFitMethod::kLbfgs);
  EXPECT_THROW_MESSAGE(StarfishRecordingTerm(lbfgs, kCyclic1, Options(), recordings_), InvalidInputError,
                       "the starfish recordings fit needs the lm fit and no material regions");
  StarfishRecordingsOptions outside = recordings_;
  outside.guess.youngs_modulus = 6e6;
  EXPECT_THROW_MESSAGE(StarfishRecordingTerm(starfish_, kCyclic1, Options(), outside), InvalidInputError,
                       "youngs_modulus = 6e+06 is outside the fit's interval (1e4, 5e6) Pa");
}

}  // namespace
}  // namespace diffpd::problems
