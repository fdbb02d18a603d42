// `diffpd tradeoff`: time against error for each solver method, sweeping
// (1) the solve tolerance, (2) the time step and (3) the mesh resolution,
// each against a converged reference (newton-cholesky, rel_tolerance 1e-10,
// see bench.h). Loss, gradient and error norms are those of bench.h.
//
//  - tolerance: the problem at its time step and mesh; each method with
//    rel_tolerance = backward_rel_tolerance = each value of `tolerances`.
//    Reference: the same rollout, converged.
//  - time_step: a fixed simulated duration T = steps * h0; h = h0 / 2^k for
//    k = 0 .. time_step_levels - 1 (steps * 2^k steps), each method at
//    rel_tolerance. Reference: converged at h0 / 2^time_step_levels. The state
//    and gradient compared are those at T (same loss vectors).
//  - resolution: the mesh with refine - 3 j doublings (j = levels-1 .. 0, each
//    coarser level has half the cells per axis), each method at rel_tolerance.
//    States of different meshes are compared through the 8 nodes nearest the
//    corners of the rest bounding box: state_rel_error is the relative error of
//    their final displacements (24 numbers), grad_rel_error that of
//    (E dL/dE, nu dL/dnu, rho dL/drho) for L = c . (those 24 positions).
//    Reference: converged on the finest mesh (the problem's own).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/solver_options.h"

namespace diffpd::problems {

struct TradeoffOptions {
  std::vector<Method> methods = {Method::kPd, Method::kPdLbfgs, Method::kNewtonPcg, Method::kNewtonCholesky};
  // Values of the tolerance sweep (forward and backward relative tolerance).
  std::vector<double> tolerances = {1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8};
  // Tolerance of the time-step and resolution sweeps.
  double rel_tolerance = 1e-4;
  int steps = -1;         // <= 0: the problem's default
  double time_step = -1;  // h0; <= 0: the problem's default (s)
  int threads = 0;
  int max_iterations = 1000;  // of each step's solve (the references use it too)
  int refine = 0;             // mesh of the tolerance and time-step sweeps, finest of the resolution sweep
  int time_step_levels = 4;   // >= 1
  int resolution_levels = 4;  // >= 1
  bool sweep_tolerance = true;
  bool sweep_time_step = true;
  bool sweep_resolution = true;
  std::uint64_t seed = 20211;

  // Throws InvalidInputError naming the field, its value and the valid range.
  void Validate() const;
};

struct TradeoffRow {
  std::string sweep;  // "tolerance", "time_step" or "resolution"
  std::string method;
  std::string parameter;  // "rel_tolerance", "time_step" (s) or "elements"
  double value = 0;
  std::string failure;  // "" when the run succeeded
  double seconds = 0;   // forward_s + backward_s
  double forward_s = 0, backward_s = 0, iters_per_step = 0;
  double state_rel_error = 0, grad_rel_error = 0;
  int dofs = 0, steps = 0;
};

// Runs the enabled sweeps on the registered problem `problem` (one that
// MakeRefinedProblem accepts). Progress lines go to `progress` (nullptr:
// silent). Throws InvalidInputError on bad options and SolverError when a
// reference fails.
std::vector<TradeoffRow> RunTradeoff(const std::string& problem, const TradeoffOptions& options,
                                     std::ostream* progress = nullptr);

// Rows as a JSON list of {sweep, method, parameter, value, seconds,
// state_rel_error, grad_rel_error, status, forward_s, backward_s,
// iters_per_step, dofs, steps}; a failed run has null numbers.
nlohmann::json TradeoffToJson(const std::vector<TradeoffRow>& rows);

// True when a `gnuplot` executable is on PATH.
bool GnuplotAvailable();
// `s` as a gnuplot single-quoted string ('' is a quote). Throws
// InvalidInputError for a line break ("plot path contains a line break: give
// a plain file name").
std::string GnuplotQuote(const std::string& s);
// Runs gnuplot on `script`, which writes `png_path`. Throws
// std::runtime_error when gnuplot cannot start, fails, or writes no file.
void RunGnuplot(const std::string& script, const std::string& png_path);
// Writes a PNG of the rows with gnuplot: one column per sweep, top row state
// error and bottom row gradient error against seconds, log-log, one curve per
// method (zero errors drawn at 1e-17). Throws std::runtime_error when gnuplot
// is missing or fails, InvalidInputError for a path gnuplot cannot quote.
void WriteTradeoffPlot(const std::vector<TradeoffRow>& rows, const std::string& png_path, const std::string& title);

}  // namespace diffpd::problems
