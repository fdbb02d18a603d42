// A Monte Carlo check of the standard deviations that the starfish's
// least-squares fit reports (FitStarfishLeastSquares, ceres::Covariance):
// synthetic recordings are simulated from known parameters, Gaussian noise
// of known size is added to every weighted marker coordinate, each is
// refitted from the known parameters, and the spread of the refitted values
// is compared with the standard deviations the refits report.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calibration/starfish_actuation.h"
#include "calibration/starfish_fit.h"
#include "diffpd/captured_motion.h"
#include "diffpd/material.h"
#include "diffpd/solvers/core/rollout_function.h"

namespace diffpd::problems {

// The parameters the synthetic recordings are made from (and the refits
// start at). With `water` the models have the water block and the refits
// fit it too.
struct StarfishTruth {
  MaterialParameters material;
  StarfishActuation actuation;
  std::optional<StarfishWater> water;
};

// The model of a captured motion: a rollout function with the blocks of
// FitStarfishLeastSquares (material {E, nu}, the tendon actuation, and the
// water when StarfishTruth::water is set) whose functional 0 is the
// MarkerResiduals of `motion`.
using StarfishModelFactory = std::function<std::unique_ptr<solvers::RolloutFunction>(const CapturedMotion& motion)>;

struct StarfishCovarianceCheckOptions {
  int refits = 30;          // synthetic recordings, >= 2
  double noise = 0.1;       // standard deviation of each weighted residual (weight * m), > 0
  std::uint64_t seed = 1;   // of the noise (std::mt19937_64)
  int max_iterations = 20;  // Levenberg-Marquardt iterations per refit
};

struct StarfishCovarianceCheck {
  // Per fitted value (FitStarfishLeastSquares' order): its name, the truth,
  // the mean and the standard deviation of the refitted values, and the
  // median of the standard deviations the refits reported.
  std::vector<std::string> names;
  std::vector<double> truth, mean, empirical_sd, reported_sd;
  int refits = 0;  // refits run
  int usable = 0;  // of them usable, with a covariance (the statistics' sample)
  double seconds = 0;
};

// Runs the check: the synthetic positions are the simulated marker
// positions at `truth` of `layout`'s markers and sample times (layout's
// positions only serve to recover them from the residuals; its weights are
// kept), plus noise / weight on every axis of non-zero weight. Throws
// InvalidInputError for options out of range ("refits = 1 is invalid: must
// be >= 2", "noise = 0 is invalid: must be finite and > 0"), and what
// make_model and FitStarfishLeastSquares throw; std::runtime_error when the
// model fails at the truth or fewer than 2 refits are usable.
StarfishCovarianceCheck CheckStarfishCovariance(const StarfishModelFactory& make_model, const CapturedMotion& layout,
                                                const StarfishTruth& truth,
                                                const StarfishCovarianceCheckOptions& options);

}  // namespace diffpd::problems
