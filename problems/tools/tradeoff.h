// `diffpd tradeoff`: time against error of a problem's own loss and its
// gradient with respect to the problem's own optimisation variables
// (problem_objective.h), for every problem, against a converged reference of
// the same problem (newton-cholesky, rel_tolerance 1e-10, adjoint 1e-12, no
// contact screening, the contact energy guard at kReferenceMaxEnergyGain;
// cached on disk by reference_cache.h). Every run starts from the problem's
// own settings (ProblemObjective::defaults) and changes what its sweep
// names:
//
//  - default: the problem's settings unchanged (the point users get).
//  - tolerance: each method with rel_tolerance = each value of `tolerances`
//    (the adjoint's tolerance follows as the problem's settings say: tied to
//    the forward's where the problem ties them, else unchanged).
//  - tolerance_reference: the default method at each tolerance with the other
//    ToleranceReference (start residual <-> inertial term).
//  - adjoint_solver: pd and pd-lbfgs (those of `methods`) at the default
//    tolerance with each AdjointSolver (auto, iterative, direct).
//  - backward_tolerance: pd and pd-lbfgs at the default tolerance with
//    backward_rel_tolerance = 0 and backward_tolerance_factor = each of
//    `backward_factors`.
//  - screening: scenes with frictional contact whose screening the objective
//    can set: the default method at the default tolerance with
//    screening_rel_tolerance = each of `screenings` (0: none).
//  - time_step (forward scenes only): a fixed duration T = steps * h0,
//    h = h0 / 2^k for k < time_step_levels, each method at the default
//    tolerance, against the reference at h0 / 2^time_step_levels, with the
//    linear loss of bench.h (state and gradient at T).
//  - resolution (cantilever, falling-cube): the mesh with refine - 3 j
//    doublings, errors of the 8 corner nodes' displacement and of
//    (E dL/dE, nu dL/dnu, rho dL/drho), L linear in their positions,
//    against the finest mesh.
//
// Errors are relative 2-norms against the reference: of the final state
// [x_K, v_K], of the loss |L - L_ref| / |L_ref| and of the gradient.
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/solver_options.h"
#include "tools/problem_objective.h"

namespace diffpd::problems {

// The converged reference's contact energy guard
// (FrictionalContactOptions::max_energy_gain; the scenes' default is 1e-4):
// a step solved to rel_tolerance 1e-10 keeps none of the solve slack that
// lets looser solves of the same step pass the guard.
inline constexpr double kReferenceMaxEnergyGain = 1e-2;

// What a row's `seconds` counts: wall-clock seconds of the forward and
// backward passes, or the process's CPU seconds of the whole evaluation
// (setup included; with threads = 1 about the wall time of an idle machine,
// and much less disturbed by other work on a shared one).
enum class TradeoffClock { kWall, kCpu };

struct TradeoffOptions {
  std::vector<Method> methods = {Method::kPd, Method::kPdLbfgs, Method::kNewtonPcg, Method::kNewtonCholesky,
                                 Method::kNewtonLdlt};
  // Values of the tolerance sweep (forward relative tolerance).
  std::vector<double> tolerances = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
  std::vector<double> backward_factors = {1, 0.1, 0.01, 0.001};
  std::vector<double> screenings = {0, 1e-1, 1e-2};
  // Tolerance of the time-step and resolution sweeps; <= 0: the problem's.
  double rel_tolerance = -1;
  double time_step = -1;  // forward scenes' h0; <= 0: the problem's default (s)
  int threads = 0;
  // Timed runs of each setting (>= 1); a row keeps its fastest run (on a
  // shared machine the least-disturbed one). Repeated runs' forward errors
  // agree up to the rounding of threaded sums, and so do their gradients
  // (adjoint_solver auto's choice is deterministic).
  int repeats = 1;
  TradeoffClock clock = TradeoffClock::kWall;
  int max_iterations = -1;  // of each step's solve; -1: the problem's (references: at least 1000)
  // The problem's instance: forward scenes' steps (<= 0: the problem's),
  // cantilever's and falling-cube's cell doublings (the finest mesh of the
  // resolution sweep), a paper row's size and masses.
  ObjectiveInstance instance;
  int time_step_levels = 4;   // >= 1
  int resolution_levels = 4;  // >= 1
  bool sweep_tolerance = true;
  bool sweep_solver_options = true;  // tolerance_reference, adjoint_solver, backward_tolerance, screening
  bool sweep_time_step = true;       // where the problem has the knob
  bool sweep_resolution = true;      // where the problem has the knob
  std::uint64_t seed = 20211;
  // Directory of the cached references ("": none).
  std::string cache_dir;

  // Throws InvalidInputError naming the field, its value and the valid range.
  void Validate() const;
};

struct TradeoffRow {
  // "default", "tolerance", "tolerance_reference", "adjoint_solver",
  // "backward_tolerance", "screening", "time_step" or "resolution"
  std::string sweep;
  std::string method;
  std::string parameter;  // "rel_tolerance", "time_step" (s), "elements", ...
  double value = 0;
  std::string setting;       // the value in words where it is not a number ("direct")
  double rel_tolerance = 0;  // the forward tolerance of the run
  std::string failure;       // "" when the run succeeded
  double seconds = 0;        // forward_s + backward_s, or cpu_s (TradeoffClock::kCpu)
  double cpu_s = 0;          // process CPU seconds of the evaluation
  double forward_s = 0, backward_s = 0, iters_per_step = 0;
  double state_rel_error = 0, loss_rel_error = 0, grad_rel_error = 0;
  int dofs = 0, steps = 0;
  // The run has the default's settings (measured again by another sweep).
  bool default_settings = false;
  bool ok() const { return failure.empty(); }
  // Runs at the problem's time step and mesh (what the front is made of).
  bool at_problem_settings() const { return sweep != "time_step" && sweep != "resolution"; }
};

struct TradeoffResult {
  std::string problem, variables, loss;
  int dofs = 0, steps = 0;
  double time_step = 0;
  std::string masses;  // a paper row's masses ("equal-nodes", "lumped"); "" for the other problems
  std::string default_method;
  double default_rel_tolerance = 0;
  bool reference_cached = false;  // the tolerance-sweep reference came from the cache
  double reference_s = 0;         // seconds the reference took when it was computed
  int repeats = 1;                // timed runs per row (TradeoffOptions::repeats)
  TradeoffClock clock = TradeoffClock::kWall;
  std::vector<TradeoffRow> rows;  // rows[0]: the default
};

// Runs the enabled sweeps on `problem` (a name of ObjectiveProblemNames()).
// Progress lines go to `progress` (nullptr: silent). Throws
// InvalidInputError on bad options, std::runtime_error when the objective's
// reference fails and SolverError when a time-step or resolution reference
// fails.
TradeoffResult RunTradeoff(const std::string& problem, const TradeoffOptions& options,
                           std::ostream* progress = nullptr);

// The rows as a JSON list of {sweep, method, parameter, value, setting,
// rel_tolerance, seconds, state_rel_error, loss_rel_error, grad_rel_error,
// status, forward_s, backward_s, cpu_s, default_settings, iters_per_step,
// dofs, steps}; a failed run
// has null numbers.
nlohmann::json TradeoffToJson(const std::vector<TradeoffRow>& rows);
// The rows of TradeoffToJson's list (a report's "rows"). Throws
// InvalidInputError naming the row and the field that is missing or has the
// wrong type.
std::vector<TradeoffRow> TradeoffRowsFromJson(const nlohmann::json& rows);

// True when a `gnuplot` executable is on PATH.
bool GnuplotAvailable();
// `s` as a gnuplot single-quoted string ('' is a quote). Throws
// InvalidInputError for a line break ("plot path contains a line break: give
// a plain file name").
std::string GnuplotQuote(const std::string& s);
// Runs gnuplot on `script`, which writes `png_path`. Throws
// std::runtime_error when gnuplot cannot start, fails, or writes no file.
void RunGnuplot(const std::string& script, const std::string& png_path);
// Writes a PNG of the rows with gnuplot: one column per sweep present
// (tolerance, time_step, resolution; the solver-option sweeps drawn as points
// in the tolerance column), top row state error and bottom row gradient
// error against seconds, log-log, one curve per method (zero errors drawn at
// 1e-17), the default marked; the time axis says what `clock` counted.
// Throws std::runtime_error when gnuplot is missing or fails,
// InvalidInputError for a path gnuplot cannot quote.
void WriteTradeoffPlot(const std::vector<TradeoffRow>& rows, const std::string& png_path, const std::string& title,
                       TradeoffClock clock = TradeoffClock::kWall);

}  // namespace diffpd::problems
