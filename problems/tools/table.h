// `diffpd table`: the DiffPD paper's results table (PROBLEMS.md rows 1-11)
// measured here, beside the paper's numbers.
//
// Per row: the row is built at the paper's size (or small), its preparatory
// simulations run (targets, with pd-lbfgs), then the loss of each of its 16
// random draws is evaluated with pd-lbfgs (forward only: L_random, the
// normalisation, and the torus's x_init, the best draw). Then, per method, a
// fresh simulator evaluates the loss and its gradient at x_init
// (PaperRow::initial) `evaluations` times (Newton methods
// `newton_evaluations` times); forward_s and backward_s are the means of
// Simulator::Simulate and Simulator::Backward (+ the pull-back onto the
// variables) wall seconds, the first evaluation including the simulator's
// one-off PD factorisation. The loss reported is the last evaluation's,
// normalised (L - l) / (L_random - l) with l = 0, or pd-lbfgs's loss where the
// row's baseline is DiffPD's final loss. speedup = min over the Newton
// methods of (forward_s + backward_s) / pd-lbfgs's.
//
// The run checkpoints: after every random draw and every method the whole
// result so far goes to the `checkpoint` callback (the command writes the
// JSON file there), and a run given a previous result (resume) keeps its
// finished methods and draws. A run stops when its wall-clock budget is
// spent, before the next evaluation; what it measured is kept.
#pragma once

#include <functional>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/solver_options.h"
#include "paper/paper_row.h"
#include "paper/row_optimisation.h"

namespace diffpd::problems {

struct TableOptions {
  // Row names (paper_rows.h), in the order to run them.
  std::vector<std::string> rows;
  // Methods measured per row, in this order.
  std::vector<Method> methods = {Method::kPdLbfgs, Method::kNewtonPcg, Method::kNewtonCholesky};
  int threads = 2;  // SolverOptions::num_threads (0: OpenMP's default)
  // Wall-clock budget of the run in minutes; <= 0: none.
  double budget_minutes = 0;
  RowSize size = RowSize::kPaper;
  // The rows' masses: the original code's (rho dx^3 on every node, so the
  // rows are the paper's problems) or this library's lumped masses.
  MassLumping masses = MassLumping::kEqualNodes;
  // Random draws evaluated per row in this run, at most the row's 16 (the
  // normalisation; the torus's x_init is the best of all 16, the first draw
  // until all are done). Fewer leave the row incomplete for a later resume.
  int random_draws = 16;       // >= 0
  int evaluations = 3;         // loss + gradient evaluations per PD method (pd, pd-lbfgs), >= 1
  int newton_evaluations = 1;  // per Newton method, >= 1
  // false: measure nothing; only rebuild the report of `previous` (RunTable).
  bool measure = true;
  // After the evaluations at x_init, optimise every optimised row with each
  // PD method (pd-lbfgs, pd) through row_optimisation.h with `optimizer`
  // (L-BFGS-B, the paper's, or Ipopt; the row's bounds and budget); the
  // Newton methods are timed at x_init only. Ipopt needs the Ipopt adapter
  // (InvalidInputError otherwise).
  bool optimise = false;
  RowOptimizer optimizer = RowOptimizer::kLbfgsb;
  // Loss evaluations per optimisation; <= 0: the row's budget (maxfun).
  int optimiser_evaluations = 0;
  // Wall-clock minutes per optimisation (it stops at its next iteration); <= 0: none.
  double optimiser_minutes = 0;
  // The command line that runs the table, stored in the result ("" : none).
  std::string command;

  TableOptions();  // rows = every row
  // Throws InvalidInputError naming the field, its value and the valid range
  // (an unknown row lists the valid names; semi-implicit is refused).
  void Validate() const;
};

// One optimisation of a row with one method (row_optimisation.h).
struct TableOptimisation {
  std::string optimizer;   // "lbfgsb" or "ipopt"
  std::string status;      // L-BFGS-B's stop or Ipopt's return status
  std::string stopped_by;  // RowOptimisationResult::stopped_by
  int iterations = 0;
  long evaluations = 0, gradients = 0, failed_evaluations = 0;
  double forward_s = 0, backward_s = 0;  // means per rollout and per adjoint pass
  double total_s = 0;
  double initial_loss = 0, final_loss = 0;
  std::optional<double> normalised_loss;  // of final_loss
  std::vector<double> loss_history;       // per iteration
};

struct TableMethodResult {
  std::string method;
  std::string failure;    // "" unless an evaluation failed (SolverError or invalid input)
  int evaluations = 0;    // evaluations done
  double forward_s = 0;   // mean over the evaluations
  double backward_s = 0;  // mean over the evaluations
  // Every evaluation's seconds, in order (for medians on a noisy machine).
  std::vector<double> forward_samples, backward_samples;
  double loss = 0;  // L at the last evaluation
  std::optional<double> normalised_loss;
  double iterations_per_step = 0;                 // forward solver iterations per step, last evaluation
  int newton_fallback_steps = 0;                  // pd-lbfgs steps finished by Newton, last evaluation
  double backward_iterations_per_step = 0;        // adjoint solver iterations per step, last evaluation
  int backward_fallbacks = 0;                     // adjoint solves that fell back to a direct one, last evaluation
  bool complete = false;                          // all its evaluations at x_init done (or it failed)
  std::optional<TableOptimisation> optimisation;  // when the row was optimised with this method
};

struct TableRowResult {
  std::string row;
  std::string title;
  int table_index = 0;
  std::string size;  // "paper" or "small"
  int nodes = 0, dofs = 0, elements = 0, steps = 0, variables = 0;
  double time_step = 0;
  // Where the losses are evaluated: "x_init" (no optimiser yet), and how
  // x_init was chosen.
  std::string evaluation_point = "x_init";
  std::string initial_guess;
  // Random draws' losses (pd-lbfgs), in order; their mean is L_random.
  std::vector<double> random_losses;
  int random_draws = 0;  // how many the row has (16, or 0 for a timing row)
  std::optional<double> random_loss_mean;
  std::optional<double> baseline;  // l
  std::vector<TableMethodResult> methods;
  std::optional<double> speedup;
  PaperTableNumbers paper;
  std::vector<std::string> notes;
  bool complete = false;

  const TableMethodResult* method(const std::string& name) const;
};

struct TableResult {
  std::string date;     // UTC, ISO 8601, of the first run
  std::string commit;   // git commit of the sources ("unknown" without git), of the first run
  std::string machine;  // "<cores>-core <arch>, <CPU model>"
  int threads = 0;
  std::string size;
  std::string masses = "lumped";  // ToString(MassLumping) of the rows' masses
  // The optimiser of --optimise (ToString(RowOptimizer)); files written
  // before it was an option were optimised with Ipopt.
  std::string optimizer = "ipopt";
  std::string command;  // the command line of the first run ("" if not stored)
  int evaluations = 0, newton_evaluations = 0;
  bool budget_exhausted = false;
  // "<date>, commit <commit>, <machine>[: <command>]" of each later run that
  // resumed this result.
  std::vector<std::string> resumed_runs;
  std::vector<TableRowResult> rows;
};

// Runs the table. `previous` (may be nullptr) is a result to resume from: its
// complete rows and methods and its random-draw losses are kept, and so are
// its date, commit, machine and command, this run being added to resumed_runs
// (it must have the same size, masses, threads, evaluation counts and, when it
// optimises, optimizer; InvalidInputError otherwise). `checkpoint` (may be empty) receives the whole result after
// every draw and method; progress lines (one per evaluation) go to
// `progress` (nullptr: silent). Throws InvalidInputError on bad options.
TableResult RunTable(const TableOptions& options, const TableResult* previous,
                     const std::function<void(const TableResult&)>& checkpoint, std::ostream* progress = nullptr);

// The result as JSON (numbers that are unknown are null) and back. FromJson
// throws InvalidInputError naming the first missing or ill-typed field.
nlohmann::json TableToJson(const TableResult& result);
TableResult TableFromJson(const nlohmann::json& json);

}  // namespace diffpd::problems
