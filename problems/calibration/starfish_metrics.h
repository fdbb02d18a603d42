// Errors of a predicted starfish motion against a recording, and the trivial
// predictions it must beat.
//
// Only displacements are compared (FACTS.md): per camera frame j of a window
// and marker m, the simulated x and z displacement of the marker's vertex
// against the recording's x and minus y displacement, both relative to the
// window's first frame (frame 0, excluded from every error: zero by
// construction).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "calibration/starfish_recording.h"
#include "diffpd/rollout.h"

namespace diffpd::problems {

// Weights of M1..M4's squared errors in the fit and in weighted_rms (the
// original calibration's).
inline constexpr std::array<double, 4> kStarfishMarkerWeights = {10, 1, 1, 10};

// Per frame of a window, the (x, z) displacements of M1..M4 (m).
using StarfishDisplacements = std::vector<std::array<Eigen::Vector2d, 4>>;

// The recording's displacements over the window's frames.
StarfishDisplacements CapturedDisplacements(const StarfishRecording& recording, const StarfishWindow& window);
// The simulated displacements of the marker vertices at every substeps-th
// state (frame j is state j * substeps) for `frames` frames. Throws
// InvalidInputError if the states do not cover them.
StarfishDisplacements SimulatedDisplacements(const std::array<int, 4>& vertices, const std::vector<State>& states,
                                             int substeps, int frames);

// Marker displacement errors, metres.
struct StarfishErrors {
  double rmse = 0;               // sqrt(mean over frames 1.. and markers of |d_sim - d_cap|^2), (x, z)
  double arm_relative_rmse = 0;  // the same after subtracting each frame's mean x displacement of the markers
  double weighted_rms = 0;       // sqrt(sum w_m |d_sim - d_cap|^2 / sum w_m) averaged over frames
  int frames = 0;                // frames compared (frame 0 excluded)
};
// Errors of `predicted` against `captured` (same number of frames; throws
// InvalidInputError otherwise).
StarfishErrors CompareDisplacements(const StarfishDisplacements& predicted, const StarfishDisplacements& captured);

// The trivial predictions of a recording's window: no motion at all, and
// every marker held at its mean displacement over the window (computed from
// the recording it predicts: an upper bound on what any constant prediction
// achieves).
struct StarfishBaselines {
  StarfishErrors zero_motion;
  StarfishErrors mean_displacement;
};
StarfishBaselines BaselineErrors(const StarfishDisplacements& captured);

}  // namespace diffpd::problems
