// `diffpd bench`: forward and backward cost of each solver method on a
// problem, and its error against a tightly converged Newton reference.
//
// What is measured. One rollout of K steps from the problem's initial state
// with its default inputs, and the reverse-mode gradient of the fixed random
// linear loss
//   L = c_x . x_K + c_v . v_K,   c_x, c_v ~ N(0, 1) per entry (seed `seed`).
// The "gradient" compared is the concatenation
//   [dL/dx_0 (3n), dL/dv_0 (3n), dL/dE (per Pa), dL/dnu, dL/drho (per kg/m^3)],
// followed by every step's dL/d(activation) for a scene with muscles.
// The reference is newton-cholesky with rel_tolerance 1e-10 and
// backward_rel_tolerance 1e-12 (kReferenceRelTolerance). Errors are relative
// 2-norms ||a - ref|| / ||ref|| of the final state [x_K, v_K] and of the
// gradient.
//
// Timings are wall-clock seconds of Simulator::Simulate (forward, including
// the lazy PD factorisation of a fresh simulator) and Simulator::Backward,
// the median over `repeat` runs, each run on a fresh Simulator.
#pragma once

#include <cstdint>
#include <array>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/error.h"
#include "diffpd/rollout.h"
#include "diffpd/simulator.h"
#include "diffpd/solver_options.h"
#include "problem.h"

namespace diffpd::problems {

// Forward tolerance of the reference rollout (newton-cholesky).
inline constexpr double kReferenceRelTolerance = 1e-10;
// Tolerance of the reference's adjoint solves.
inline constexpr double kReferenceBackwardRelTolerance = 1e-12;

// The range of MakeRefinedProblem's doublings: -9 leaves the cantilever
// 4 x 1 x 1 cells and the cube 1; 12 multiplies the cells by 4096 (8.4
// million hexes for the cantilever), beyond what a run on one machine holds.
inline constexpr int kMinRefinement = -9;
inline constexpr int kMaxRefinement = 12;
// The most cells along one axis of a cantilever given by its cells.
inline constexpr int kMaxCantileverCells = 4096;

// The registered problem `name` with its cell count doubled `doublings` times
// (cycling over x, y, z; a negative count halves z, y, x in turn), so that
// `doublings` = 3 is 8x the elements and -3 an eighth. Cantilever: the default
// 32 x 8 x 8 cells; -9 gives 4 x 1 x 1. Falling cube: 8^3 cells, scaled to
// round(8 * 2^(doublings / 3)) cells per axis (exact for multiples of 3);
// likewise the bouncing ball's voxel grid (8 cells per axis by default: -6
// gives 2, -9 a single hexahedron) and the rolling sphere's (10: -6 gives 3,
// 19 cells whose centre is inside, -9 one), at least one cell per axis.
// With 0 doublings, any registered problem (MakeProblem). Throws
// InvalidInputError for an unknown problem (MakeProblem's message, listing
// the problems), for other problems with doublings != 0, and for doublings
// outside [kMinRefinement, kMaxRefinement]: "refinement = 100 is invalid for
// cantilever: it must be in [-9, 12] (12: 4096 times the cells)".
// `cantilever_cells` (cantilever only; all 0: its 32 x 8 x 8) are the cells
// along x, y, z that the doublings start from.
std::unique_ptr<Problem> MakeRefinedProblem(const std::string& name, int doublings,
                                            const std::array<int, 3>& cantilever_cells = {0, 0, 0});

// "NXxNYxNZ" (e.g. "172x43x43") as three cell counts; throws
// InvalidInputError: "cells = '12x3' is invalid: must be three cell counts
// NXxNYxNZ, e.g. 172x43x43". MakeRefinedProblem checks their range.
std::array<int, 3> ParseCells(const std::string& text);

// Methods from their names (ParseMethod each); throws InvalidInputError.
std::vector<Method> ParseMethods(const std::vector<std::string>& names);

// The loss above for a simulator with n DoFs.
struct LinearLoss {
  VectorXd cx, cv;  // 3n each
  static LinearLoss Random(int num_dofs, std::uint64_t seed);
  double Value(const State& final_state) const { return cx.dot(final_state.x) + cv.dot(final_state.v); }
};

// One measured forward + backward run. `failure` is empty on success, else
// "<SolverStatus>: <message>" of the SolverError that stopped it.
struct RolloutMeasurement {
  std::string failure;
  SolverStatus status = SolverStatus::kConverged;  // of the failure
  double forward_s = 0;
  double backward_s = 0;
  long total_iterations = 0;
  double iters_per_step = 0;
  // Seconds of the forward spent factorising the PD matrix (the one-off cost
  // per mesh, h and weights, Simulator::pd_factorization_seconds; 0 for
  // Newton, whose factorisations are per iteration), median of the runs.
  double factorization_s = 0;
  // Backward: iterations of the iterative adjoint solves (PD's
  // A-preconditioned CG, Newton-PCG's CG; 0 for a direct solve) and solves
  // that fell back to a direct one, of the last run.
  long backward_iterations = 0;
  int backward_fallbacks = 0;
  // Backward steps solved iteratively and by a factorisation of the step
  // Hessian (BackwardReport), of the last run.
  int backward_iterative_steps = 0;
  int backward_direct_steps = 0;
  // Bytes of the PD factor's copy for parallel solves (0: none, CHOLMOD
  // solves; Simulator::pd_factor_copy_bytes), of the last run.
  double factor_copy_bytes = 0;
  // Forward steps of the last run that ended at the rounding floor or were
  // finished by Newton after a PD-LBFGS stall (StepReport).
  int rounding_floor_steps = 0;
  int newton_fallback_steps = 0;
  State final_state;
  // [dL/dx0, dL/dv0, dL/dE, dL/dnu, dL/drho] (6n + 3), then, for a scene
  // with muscles, dL/da of every step's activations in step order (K x
  // muscles more).
  VectorXd gradient;
  bool ok() const { return failure.empty(); }
};

// Runs `repeat` (>= 1) rollouts of `inputs` from `initial` on fresh
// simulators of (scene, options) and the backward pass of `loss`; times are
// medians. SolverError is caught into `failure`, and so is a non-finite
// final state or gradient returned without one; InvalidInputError propagates.
RolloutMeasurement MeasureRollout(const Scene& scene, const SolverOptions& options, const State& initial,
                                  const std::vector<StepInput>& inputs, const LinearLoss& loss, int repeat = 1);

// ||a - ref||_2 / ||ref||_2 (||a - ref||_2 when ref = 0).
double RelativeError(const VectorXd& a, const VectorXd& ref);
// [x; v] of a state.
VectorXd StackState(const State& s);

struct BenchOptions {
  // Methods measured, in this order.
  std::vector<Method> methods = {Method::kPd, Method::kPdLbfgs, Method::kNewtonPcg, Method::kNewtonCholesky};
  double rel_tolerance = 1e-4;  // forward rel_tolerance of every method
  // Adjoint tolerance; <= 0: the library's default (SolverOptions::
  // backward_rel_tolerance = 0, derived per step from the forward's accuracy).
  double backward_rel_tolerance = -1;
  AdjointSolver adjoint_solver = SolverOptions().adjoint_solver;       // PD methods' backward and tangents
  int steps = -1;                                                      // <= 0: the problem's default
  double time_step = -1;                                               // <= 0: the problem's default (s)
  int threads = 0;                                                     // SolverOptions::num_threads
  int max_iterations = 1000;                                           // SolverOptions::max_iterations of each step
  double lbfgs_weight_scale = SolverOptions().lbfgs_weight_scale;      // pd-lbfgs preconditioner
  bool rigid_mode_correction = SolverOptions().rigid_mode_correction;  // pd-lbfgs, PD backward
  int repeat = 1;                                                      // runs per method (median), >= 1
  int refine = 0;                                                      // MakeRefinedProblem doublings
  // The cantilever's cells along x, y, z before the doublings, each in [1,
  // kMaxCantileverCells]; all 0 (default): the problem's 32 x 8 x 8.
  std::array<int, 3> cantilever_cells = {0, 0, 0};
  // SolverOptions::pd_factor_copy_max_bytes in GiB; < 0 (default): the
  // library's default.
  double factor_copy_max_gib = -1;
  std::uint64_t seed = 20211;  // loss vectors

  // Throws InvalidInputError naming the field, its value and the valid range.
  void Validate() const;
};

// The range of the tools' thread counts, for their messages: "in [0, 8]
// (0: OpenMP default; SolverOptions::num_threads)".
std::string ThreadRange();

struct BenchRow {
  std::string method;
  std::string failure;  // "" when the method succeeded
  double forward_s = 0;
  double backward_s = 0;
  double iters_per_step = 0;
  double backward_iters_per_step = 0;   // adjoint solver iterations per step (0: direct)
  int backward_fallbacks = 0;           // adjoint solves that fell back to a direct solve
  int backward_iterative_steps = 0;     // backward steps solved by an iteration
  int backward_direct_steps = 0;        // and by a factorisation of the step Hessian
  int rounding_floor_steps = 0;         // forward steps ended at the rounding floor
  int newton_fallback_steps = 0;        // PD-LBFGS steps finished by Newton after a stall
  double forward_per_iteration_ms = 0;  // forward_s / total iterations, ms
  double factorization_s = 0;           // RolloutMeasurement::factorization_s
  double state_rel_error = 0;           // of [x; v] stacked
  double position_rel_error = 0;        // of x alone
  double velocity_rel_error = 0;        // of v alone (about |x error| / h: the strictest part)
  double grad_rel_error = 0;
  // Relative errors of the gradient's parts: "x0", "v0", "youngs_modulus",
  // "poissons_ratio", "density", and "activation" for a scene with muscles.
  std::map<std::string, double> grad_rel_error_by_input;
  // (forward_s + backward_s) of newton-cholesky in this run over this
  // method's; empty when newton-cholesky is not among the methods or failed.
  std::optional<double> speedup_vs_newton_cholesky;
  // The same against the faster of newton-cholesky and newton-pcg (this
  // library's best Newton), and against newton-ldlt (the paper's Newton);
  // empty when none of them ran successfully.
  std::optional<double> speedup_vs_best_newton;
  std::optional<double> speedup_vs_newton_ldlt;
};

struct BenchResult {
  std::string problem;
  int dofs = 0, elements = 0, steps = 0;
  double time_step = 0;
  double reference_forward_s = 0;
  std::vector<BenchRow> rows;
};

// Measures every method and the reference. Progress lines go to `progress`
// (nullptr: silent). A method that fails (SolverError, or InvalidInputError
// such as PD on a non-projective energy) gets a row with `failure`. Throws
// InvalidInputError on bad options or problem, and SolverError when the
// reference itself fails.
BenchResult RunBench(const std::string& problem, const BenchOptions& options, std::ostream* progress = nullptr);

// The rows as the JSON list the command prints: objects with method,
// forward_s, backward_s, iters_per_step, state_rel_error, grad_rel_error,
// forward_per_iteration_ms, speedup_vs_newton_cholesky,
// speedup_vs_best_newton, speedup_vs_newton_ldlt (null if unknown),
// grad_rel_error_by_input, backward_iters_per_step, backward_fallbacks,
// backward_iterative_steps, backward_direct_steps, rounding_floor_steps,
// newton_fallback_steps, status ("ok" or "failed: ..."), and the run's
// problem, dofs, steps, time_step, rel_tolerance, adjoint_solver. A failed
// method has null numbers.
nlohmann::json BenchToJson(const BenchResult& result, const BenchOptions& options);

// --scaling: the problem at several element counts (factors, powers of 2;
// default 1, 2, 4, 8) with each method at rel_tolerance. PD-type methods run
// to tolerance, so the iteration count varies with the mesh; the comparable
// cost is the forward time per iteration. Reports also the process's peak
// resident memory after each size (getrusage, a high-water mark).
struct ScalingRow {
  std::string method;
  int factor = 1;
  int elements = 0, vertices = 0, dofs = 0;
  std::string failure;
  double forward_s = 0, backward_s = 0, iters_per_step = 0;
  double forward_per_iteration_ms = 0;  // forward_s / iterations
  double factorization_s = 0;           // PD's one-off factorisation within forward_s
  double iteration_ms = 0;              // (forward_s - factorization_s) / iterations
  double backward_per_step_ms = 0;
  int backward_direct_steps = 0;  // backward steps solved by a factorisation of H
  double factor_copy_mib = 0;     // the PD factor's copy (0: CHOLMOD solves)
  double peak_rss_mib = 0;
};
struct ScalingResult {
  std::vector<ScalingRow> rows;
  // Per method: least-squares slope of log(iteration_ms) against log(dofs)
  // (1 = linear), and the same for forward_per_iteration_ms, which includes
  // the one-off factorisation spread over this run's few iterations.
  std::map<std::string, double> exponent_per_iteration;
  std::map<std::string, double> exponent_with_factorization;
};
ScalingResult RunScaling(const std::string& problem, const BenchOptions& options, const std::vector<int>& factors,
                         std::ostream* progress = nullptr);
nlohmann::json ScalingToJson(const ScalingResult& result);

// --threads-compare: each method with num_threads 1 and 2. The whole step is
// the forward time per step; the local step is approximated by
// Simulator::ElasticEnergy(x) alternating between the last two states (one
// SVD-based projection per quadrature point, the PD local step's work, with
// the SVDs warm-started a step away), timed over `energy_evaluations`.
struct ThreadsRow {
  std::string method;
  std::string failure;
  double step_s_1 = 0, step_s_2 = 0;          // forward seconds per step
  double backward_s_1 = 0, backward_s_2 = 0;  // whole backward pass
  double local_ms_1 = 0, local_ms_2 = 0;      // one ElasticEnergy evaluation
  double step_speedup() const { return step_s_2 > 0 ? step_s_1 / step_s_2 : 0; }
  double backward_speedup() const { return backward_s_2 > 0 ? backward_s_1 / backward_s_2 : 0; }
  double local_speedup() const { return local_ms_2 > 0 ? local_ms_1 / local_ms_2 : 0; }
};
std::vector<ThreadsRow> RunThreadsCompare(const std::string& problem, const BenchOptions& options,
                                          int energy_evaluations = 200, std::ostream* progress = nullptr);
nlohmann::json ThreadsToJson(const std::vector<ThreadsRow>& rows);

}  // namespace diffpd::problems
