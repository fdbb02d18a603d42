// Speed against accuracy where users feel it: a problem's own optimiser run
// from its own start with every evaluation at one solver tolerance, for a
// list of tolerances. A loose tolerance makes each evaluation cheaper, but
// its losses and gradients are less accurate, so the optimiser may take more
// iterations, stop early or stop somewhere worse. Each run reports its wall
// time and the loss at the point it returned, re-evaluated with converged
// settings (newton-cholesky, rel_tolerance 1e-10), so that runs at
// different tolerances are compared on the same, exact loss.
//
//   const ProblemObjective objective = MakeProblemObjective("bunny", 1);
//   OptimiserTradeoff t = RunOptimiserTradeoff(objective, {1e-2, 1e-4, 1e-6}, {}, &std::cerr);
//
// The optimisers are each problem's own (ProblemObjective::optimiser); the
// forward scenes have none (ProblemObjective::optimise is empty).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tools/problem_objective.h"

namespace diffpd::problems {

struct OptimiserTradeoffOptions {
  // Budget of each run: Ipopt iterations, Ceres iterations or Adam
  // evaluations; <= 0: the problem's own (small instance).
  int max_iterations = 0;
};

struct OptimiserTradeoffRow {
  double rel_tolerance = 0;
  OptimiserOutcome outcome;
  // (final_loss - best) / (initial_loss - best), best the lowest final loss
  // of the runs: the fraction of the improvement the best run achieved that
  // this run fell short of (0 for the best; NaN when no run improved).
  double shortfall = 0;
};

struct OptimiserTradeoff {
  std::string problem;
  std::string optimiser;  // in words
  std::string loss;       // in words
  std::string method;     // the method every run's evaluations use (the problem's default)
  double default_rel_tolerance = 0;
  int dofs = 0, steps = 0;
  std::vector<OptimiserTradeoffRow> rows;  // one per tolerance, loosest first
};

// Runs the tolerances and the problem's default tolerance (added when not
// among them), loosest first. Throws InvalidInputError when the problem has no optimiser here, for an
// empty tolerance list or a tolerance outside (0, 1). A failed run is a
// row with outcome.failure set; progress lines go to `progress` (may be null).
OptimiserTradeoff RunOptimiserTradeoff(const ProblemObjective& objective, const std::vector<double>& tolerances,
                                       const OptimiserTradeoffOptions& options, std::ostream* progress);

nlohmann::json OptimiserTradeoffJson(const OptimiserTradeoff& tradeoff);

// The report OptimiserTradeoffJson wrote, read back (to re-plot it).
// Throws InvalidInputError naming what is missing or mistyped.
OptimiserTradeoff OptimiserTradeoffFromJson(const nlohmann::json& report);

// Shortfall (0 drawn at 1e-16) against wall time, log-log, one labelled
// point per tolerance, the default's tolerance marked. Needs gnuplot
// (GnuplotAvailable); throws std::runtime_error when the plot cannot be
// written or no run improved on the start.
void WriteOptimiserTradeoffPlot(const OptimiserTradeoff& tradeoff, const std::string& png_path);

}  // namespace diffpd::problems
