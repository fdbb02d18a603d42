// One row of the DiffPD paper's results table (PROBLEMS.md, rows 1-11) as
// data: the scene at the paper's size (or a reduced one for tests), the
// rollout it starts from, the optimisation variables and how they map to the
// rollout's inputs (solvers::ParameterBlock blocks), the loss as weighted
// functions of the rollout, the random draws that normalise the loss, the
// optimiser's budget, the solver settings and the paper's own numbers.
//
//   PaperRow row = MakePaperRow("bunny", RowSize::kPaper);   // paper_rows.h
//   Simulator sim(row.scene, row.Options(Method::kPdLbfgs, 2));
//   RowEvaluation e = EvaluateRow(row, &sim, row.initial(), true);  // row_evaluation.h
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "diffpd/scene.h"
#include "diffpd/simulator.h"
#include "diffpd/solver_options.h"
#include "diffpd/solvers/core/parameter_block.h"
#include "diffpd/solvers/core/trajectory_function.h"

namespace diffpd::problems {

// The paper's size, or a reduced instance (fewer steps, some meshes cropped
// or coarser) that runs in seconds, for tests.
enum class RowSize { kPaper, kSmall };

// One method's entry of the paper's Table: mean forward and backward seconds
// per evaluation (8 threads), evaluations and final normalised loss (both
// absent for the timing-only rows).
struct PaperMethodNumbers {
  double forward_s = 0;
  double backward_s = 0;
  std::optional<int> evaluations;
  std::optional<double> loss;
};

struct PaperTableNumbers {
  PaperMethodNumbers newton_pcg, newton_cholesky, diffpd;
  double speedup = 0;  // as printed in the Table (best Newton over DiffPD)
};

// The paper's optimiser, scipy's L-BFGS-B, and its limits (scipy defaults
// where the row sets none). A timing-only row is not optimised.
struct OptimizerBudget {
  bool optimised = true;
  double ftol = 2.220446049250313e-09;  // relative decrease of f that stops it
  int max_iterations = 15000;
  int max_evaluations = 15000;
  int history = 10;    // maxcor
  double gtol = 1e-5;  // projected-gradient tolerance
};

// How the paper normalises a loss L: (L - l) / (L_random - l), L_random the
// mean loss of the random draws (computed with the DiffPD method), l = 0 or
// DiffPD's last loss.
enum class LossBaseline { kZero, kDiffPdFinal };
// Where x_init comes from: given (draws or fixed values, held by the variable
// blocks), or the random draw with the lowest loss (torus).
enum class InitialGuess { kGiven, kBestRandomDraw };

// The solver settings the paper's script passes to every method.
struct RowSolverSettings {
  double rel_tolerance = 1e-4;
  // What rel_tolerance is relative to: the original's test (kInertia), or,
  // on a row where that test at the paper's size leaves gradients too
  // inaccurate for their cost (UseStartResidualTest), this library's.
  ToleranceReference tolerance_reference = ToleranceReference::kInertia;
  double abs_tolerance = 1e-9;  // N
  int max_iterations = 500;     // per step
  int max_line_search_steps = 10;
  int lbfgs_history = 10;
  // Threads behind the paper's numbers: 8; 0: the CPU count - 1; -1: not stated.
  int paper_threads = 8;
};

// A weighted term of the loss.
struct LossTerm {
  std::shared_ptr<const solvers::TrajectoryFunction> function;
  double weight = 1;
};

struct PaperRow {
  std::string name;     // "plant", "bunny", ...
  std::string title;    // "Plant (material identification)"
  int table_index = 0;  // the row's number in PROBLEMS.md (1-11)
  RowSize size = RowSize::kPaper;
  Scene scene;
  double time_step = 0;  // s
  int steps = 0;
  // The rollout before the variables act: initial state, K inputs (activation
  // vectors sized to the muscles where the scene has any), the material.
  solvers::RolloutSetup base;
  // The variables, block after block; a block's initial() holds x_init before
  // projection onto its bounds (the paper's L-BFGS-B projects it).
  std::vector<std::shared_ptr<solvers::ParameterBlock>> variables;
  // L = sum of weight * function(rollout).
  std::vector<LossTerm> loss;
  InitialGuess initial_guess = InitialGuess::kGiven;
  // The random parameter vectors whose mean loss is L_random (empty for a
  // timing-only row), in the order numpy drew them.
  std::vector<VectorXd> random_draws;
  LossBaseline baseline = LossBaseline::kZero;
  OptimizerBudget budget;
  RowSolverSettings solver;
  PaperTableNumbers paper;
  // How this row here differs from the original code (model, contact,
  // tolerance), one sentence each; printed with the table.
  std::vector<std::string> notes;
  // Simulations the row needs before its loss can be evaluated (plant:
  // its initial state; plant and bouncing ball: the target motion), run with
  // the given simulator options; empty when none. Prepare() runs and clears it.
  std::function<void(PaperRow*, const SolverOptions&)> prepare;

  int num_variables() const;
  VectorXd lower() const;
  VectorXd upper() const;
  // x_init projected onto the bounds (the paper's L-BFGS-B starting point).
  VectorXd initial() const;
  // x_init as drawn, before projection.
  VectorXd initial_unprojected() const;
  // Replaces x_init (num_variables() entries, finite). Throws InvalidInputError.
  void SetInitial(const VectorXd& x);

  // The rollout's setup at variables x (base, then every block's Apply).
  // Throws InvalidInputError if x has the wrong size.
  solvers::RolloutSetup Setup(const VectorXd& x) const;
  // dL/dx from the rollout gradient at the setup made from x.
  VectorXd PullBack(const VectorXd& x, const RolloutGradient& gradient) const;
  // L of a rollout and, if gradient != nullptr, dL/dx_k and dL/dv_k (sized
  // for the rollout's steps).
  double Loss(const Rollout& rollout, LossGradient* gradient) const;
  // The simulator options of `method` with the row's settings: time step,
  // tolerances (the step test of solver.tolerance_reference; the adjoint's
  // relative tolerance = rel_tolerance), iteration and line-search limits,
  // L-BFGS history, `threads` threads.
  SolverOptions Options(Method method, int threads) const;
  // Runs `prepare` once with `options` (nothing if empty).
  void Prepare(const SolverOptions& options);
};

// The model differences every row shares (masses, tolerance test, PD-LBFGS
// preconditioner, Newton-PCG's inner tolerance), and those of rows with
// frictional contact.
std::vector<std::string> CommonRowNotes();
// Gives the row's body `masses`: kEqualNodes (the original code's rho dx^3 on
// every node) or kLumped (this library's default; then a note says how it
// differs from the original).
void SetRowMasses(PaperRow* row, MassLumping masses);
std::string FrictionalContactNote();
// Gives the row this library's step test (ToleranceReference::kStartResidual)
// for every method, and replaces the note on the original's test by one that
// says so and why: `why`, what the original's test costs on this row.
void UseStartResidualTest(PaperRow* row, const std::string& why);

}  // namespace diffpd::problems
