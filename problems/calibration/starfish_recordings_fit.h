// The starfish fit (starfish_fit.h) over several recordings at once: E, nu
// and the tendon actuation (slack, lag, length) shared by all, each
// recording's window a term of a RolloutSet (diffpd/solvers/core/rollout_set.h,
// TermObjective::kLeastSquares) whose rows are its per-frame marker
// residuals (StarfishCalibration::MakeModel with the lm fit), fitted by
// Levenberg-Marquardt with exact Jacobians (forward-mode tangents, 5
// parameters) on the bounded coordinates of StarfishFitCoordinates(false),
// with the single-recording fit's Ceres settings. The cost is the sum of
// the recordings' costs, so each counts by its frames. No parameter is
// per recording (as in the single-recording fit). The same code fits on one
// process (LocalRolloutSet) or over MPI ranks (DistributedRolloutSet).
#pragma once

#include <cstdio>
#include <string>
#include <vector>

#include "calibration/calibrate_starfish.h"
#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::problems {

// The window of each recording and the fit's start.
struct StarfishRecordingsOptions {
  double start = 1.0;    // s, each window's start (>= 0)
  double seconds = 2.0;  // s, each window's length (> 0)
  MaterialParameters guess{5e5, 0.4, 400};
  StarfishActuation actuation_guess = StarfishCalibration::ActuationGuess();
};

// The term of the recording at `path`: its window (MakeStarfishWindow),
// MakeModel at the guesses (problem's fit method must be lm and its regions
// none), the marker residuals as rows. Throws what ReadStarfishRecording,
// MakeStarfishWindow and MakeModel throw, and InvalidInputError for a
// problem set up otherwise ("the starfish recordings fit needs the lm fit
// and no material regions").
solvers::RolloutTerm StarfishRecordingTerm(const StarfishCalibration& problem, const std::string& path,
                                           const SolverOptions& options, const StarfishRecordingsOptions& recordings);

// The outcome of a fit over several recordings.
struct StarfishRecordingsFit {
  // E, nu, the actuation, the summed costs, iterations, Ceres' verdict; its
  // statistics are this process's terms'; no covariance.
  StarfishFit fit;
  int evaluations = 0;  // set evaluations (residuals, with or without Jacobian)
  // Each recording's cost 1/2 |r_t|^2 at the start and at the fitted values
  // (empty where that evaluation failed).
  std::vector<double> initial_costs, final_costs;
  double seconds = 0;  // wall time of the solve
};

// Fits the set's 5 parameters (E, nu, slack, lag, length: the terms'
// parameter order) from its initial parameters, at most max_iterations
// Levenberg-Marquardt iterations; the iteration table goes to `log`
// (nullptr: silent). Call it on rank 0 of a distributed set. The fitted
// material's density is `density`.
StarfishRecordingsFit FitStarfishOverSet(solvers::RolloutSet* set, double density, int max_iterations, FILE* log);

}  // namespace diffpd::problems
