// What a trade-off sweep (tradeoff.h) says: the Pareto front of time against
// gradient error, where the problem's default sits relative to it, how far
// from the default a user may loosen the tolerance before the gradient error
// exceeds a bound, and whether the errors fall as the tolerance tightens.
// Pure functions of the rows: no simulation.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/tradeoff.h"

namespace diffpd::problems {

// A tolerance-sweep pair whose tighter tolerance gave a larger error than
// noise_factor times the looser one's (plus the floor).
struct MonotonicityViolation {
  std::string method, error;  // error: "state", "loss" or "gradient"
  double looser_tolerance = 0, tighter_tolerance = 0;
  double looser_error = 0, tighter_error = 0;
};

// For each method of the tolerance sweep, every pair of successful runs
// t_loose > t_tight: err(t_tight) <= noise_factor * err(t_loose) + floor,
// for the state, loss and gradient errors. Returns the pairs that fail.
std::vector<MonotonicityViolation> CheckMonotone(const std::vector<TradeoffRow>& rows, double noise_factor,
                                                 double floor);

// The fastest setting whose gradient error is at most `bound`, and the
// loosest tolerance of the default method that meets it.
struct ErrorBound {
  double bound = 0;
  bool met = false;  // some run reaches it
  std::string method, setting;
  double rel_tolerance = 0, seconds = 0, grad_rel_error = 0;
  // Of the default method's tolerance sweep: the loosest tolerance t whose
  // run and every tighter one's meet the bound (0: none), and t over the
  // default tolerance (how far a user may loosen it; < 1: must tighten).
  double default_method_tolerance = 0;
  double loosening = 0;
  // Of pd-lbfgs's tolerance sweep: the loosest such tolerance, its seconds,
  // and the seconds of the fastest Newton run (newton-*) meeting the bound.
  double pd_lbfgs_tolerance = 0, pd_lbfgs_seconds = 0, best_newton_seconds = 0;
};

struct TradeoffFront {
  // Indices into the rows of the runs at the problem's time step and mesh
  // that no other such run beats in both seconds and gradient error.
  std::vector<int> front;
  // The default's seconds: the least of the runs with its settings (the
  // default row and the other sweeps' runs that repeat it).
  double default_seconds = 0;
  // default_seconds over the least seconds of a run (at the problem's
  // settings) whose gradient error is at most the default's; <= 1.1: on or
  // within 10% of the front.
  double default_slowdown = 0;
  bool default_on_front = false;
  std::vector<ErrorBound> bounds;  // 1e-3, 1e-2, 1e-1
};

// Needs rows[0] to be the default run (RunTradeoff's order). Throws
// InvalidInputError when it is not.
TradeoffFront AnalyseFront(const TradeoffResult& result);

// {problem, variables, loss, dofs, steps, time_step, reference_seconds,
// reference_cached, repeats, clock ("wall" or "cpu"), default {method,
// rel_tolerance, seconds, seconds_fastest_at_its_settings, grad_rel_error,
// slowdown, on_front}, front [row indices], bounds [...],
// monotonicity_violations [...], rows [...]}.
nlohmann::json TradeoffReportJson(const TradeoffResult& result, const TradeoffFront& front,
                                  const std::vector<MonotonicityViolation>& violations);

}  // namespace diffpd::problems
