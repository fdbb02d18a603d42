// A recording of the soft starfish robot (the shared data/starfish/FACTS.md
// CSV format) and the windows of it that a simulation covers.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace diffpd::problems {

inline constexpr double kStarfishFrameRate = 60;  // Hz, the camera

// One recording: a header row, then 10 numbers per row: time (ms), tendon
// contraction (mm, NaN allowed), M1 x, M1 y, ..., M4 x, M4 y (mm, image
// plane). Stored here in SI units.
struct StarfishRecording {
  std::string path;
  std::vector<double> time;    // s, strictly increasing
  std::vector<double> tendon;  // m; NaN where the file has NaN
  // Per row: image x and image y (m) of M1..M4: {x1, y1, x2, y2, ..., x4, y4}.
  std::vector<std::array<double, 8>> markers;
  std::vector<int> lines;  // file line of each row (the header is line 1)

  int num_rows() const { return static_cast<int>(time.size()); }
};

// Reads a starfish recording. Throws InvalidInputError naming the file and
// line:
//   "cannot open '<path>'", "cannot open '<path>': it is a directory, not a file",
//   "<path>: empty file (expected a header row and data rows)",
//   "<path>:1: expected a header row of 10 column labels, got 3 fields",
//   "<path>:5: expected 10 fields (time ms, tendon mm, M1 x, M1 y, ..., M4 x, M4 y), got 9",
//   "<path>:5: M2 y is not a number: 'abc'",
//   "<path>:5: M2 y = nan is invalid: marker coordinates must be finite and within +-1e+09 (mm)"
//   (kMaxMarkerCoordinate, captured_motion.h),
//   "<path>:5: time = inf is invalid: must be finite (ms)",
//   "<path>:5: tendon = inf is invalid: must be finite or NaN (mm)",
//   "<path>:5: time 10 ms is not after the previous row's 16.6667 ms (line 4)",
//   "<path>: no data rows".
StarfishRecording ReadStarfishRecording(const std::string& path);

// The rows of a recording that a simulation covers: rows first..last, from
// the first row at or after `start` seconds to the last one within `seconds`
// after it, stopping before the first row with a NaN tendon value.
struct StarfishWindow {
  int first = 0;
  int last = 0;      // inclusive; last > first
  std::string note;  // why the window is shorter than asked ("" if it is not)
  int num_frames() const { return last - first + 1; }
};
// Throws InvalidInputError if `seconds` is not finite and > 0, if `start` is
// not finite and >= 0, if the recording has no row at or after `start`, or if
// fewer than two rows remain (e.g. the tendon is NaN from the start):
//   "<path>:<line>: tendon contraction is NaN at the window's first row (t = 33.8 s): nothing to simulate".
StarfishWindow MakeStarfishWindow(const StarfishRecording& recording, double start, double seconds);

// The simulation time step of a window with `substeps` steps per camera
// frame: the window's mean frame interval / substeps (s).
double StarfishTimeStep(const StarfishRecording& recording, const StarfishWindow& window, int substeps);

}  // namespace diffpd::problems
