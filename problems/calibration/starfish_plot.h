// Pictures of a predicted starfish motion next to its recording: per-marker
// time series as a PNG (gnuplot) and the simulated body with the captured
// markers as a ParaView time series.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "calibration/starfish_metrics.h"
#include "calibration/starfish_recording.h"
#include "diffpd/mesh.h"
#include "diffpd/rollout.h"

namespace diffpd::problems {

// Writes `png_path` with gnuplot from a trace file of WriteStarfishTrace
// (starfish_trace.h): a 4 x 2 grid, one row per marker M1..M4, x and z
// displacement (mm) against time (s), simulated and captured, with the
// recorded tendon contraction (mm, right axis) behind them; `title` on top.
// Throws std::runtime_error when gnuplot is missing, fails or writes no
// file, InvalidInputError for a path gnuplot cannot quote.
void WriteStarfishTracePlot(const std::string& trace_csv, const std::string& png_path, const std::string& title);

// Writes the simulated body of a window and its captured markers as two
// ParaView time series in `dir` (created if missing): <stem>_body.pvd
// (VTK unstructured grids of `mesh` at every `stride`-th camera frame of
// `states`, which holds substeps states per frame, with the point field
// "displacement", m) and <stem>_markers.pvd (poly data, the four captured
// markers as points at the same frames: the marker vertex's position in
// `states[0]` plus the captured x and z displacement, y kept; point field
// "simulated_error", the simulated minus the captured position, m).
// `captured` has one entry per frame. Returns the .pvd paths. Throws
// InvalidInputError for stride < 1 ("stride = 0 is invalid: must be >= 1"),
// too few states for the frames, and what PvdWriter throws.
std::array<std::string, 2> WriteStarfishVtk(const std::string& dir, const std::string& stem, const Mesh& mesh,
                                            const std::array<int, 4>& marker_vertices, const std::vector<State>& states,
                                            int substeps, const std::vector<double>& frame_times,
                                            const StarfishDisplacements& captured, int stride);

}  // namespace diffpd::problems
