// Calibration of the plant against several recordings: the scene, markers,
// capture times, noise and true material of calibrate-plant
// (calibrate_plant.h), swaying after a different gust in each recording.
// Recording i of n starts with the gust (0.3, 0.15, 0) m/s rotated by
// 2 pi i / n about the vertical axis and is synthesised like the shipped
// plant motion (newton-cholesky at relative tolerance 1e-11), with noise
// seed 2021 + i. Each recording is one term of a RolloutSet
// (diffpd/solvers/core/rollout_set.h): E and nu from calibrate-plant's
// starting guess, the marker residuals as rows.
#pragma once

#include "diffpd/captured_motion.h"
#include "diffpd/solver_options.h"
#include "diffpd/solvers/core/rollout_set.h"

namespace diffpd::problems {

struct PlantRecordingsOptions {
  int count = 4;                     // recordings, >= 1
  Method method = Method::kPdLbfgs;  // the fit's simulator
  int threads = 1;                   // per term's simulator
};

// The gust of recording i (m/s).
Vec3 PlantGust(int i, int count);
// Recording i's captured motion.
CapturedMotion SynthesizePlantRecording(int i, int count);
// Recording i's term (synthesises the recording). Throws InvalidInputError
// for i outside [0, count) or count < 1 ("plant recording 4 is out of range
// [0, 4)") and what the plant's mesh reading throws.
solvers::RolloutTerm PlantRecordingTerm(int i, const PlantRecordingsOptions& options);

}  // namespace diffpd::problems
