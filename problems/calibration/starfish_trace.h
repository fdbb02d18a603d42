// A predicted starfish motion next to its recording, per camera frame, as
// CSV for plotting.
#pragma once

#include <string>

#include "calibration/starfish_metrics.h"
#include "calibration/starfish_recording.h"
#include "diffpd/rollout.h"

namespace diffpd::problems {

// Writes <dir>/<recording stem>_trace.csv (creating dir): per frame of the
// window, time (s), tendon (mm), activation of the frame's first step, and
// per marker the simulated and captured x and z displacements (mm):
//   time_s,tendon_mm,activation,M1_sim_x,M1_cap_x,M1_sim_z,M1_cap_z,...
// `simulated` and `captured` have one entry per frame; `rollout` the frames'
// inputs (substeps per frame). Returns the path. Throws InvalidInputError if
// the file cannot be written ("cannot write '<path>'").
std::string WriteStarfishTrace(const std::string& dir, const StarfishRecording& recording, const StarfishWindow& window,
                               const Rollout& rollout, int substeps, const StarfishDisplacements& simulated,
                               const StarfishDisplacements& captured);

}  // namespace diffpd::problems
