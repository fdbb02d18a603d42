// `diffpd bench`: the command-line edge of bench.h.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <memory>

#include "tools/bench.h"
#include "cli/commands.h"
#include "cli/option_checks.h"
#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

constexpr const char* kBenchFooter = R"(
Measures one rollout (the problem's steps, or --steps) and its backward pass
per method. The loss is L = c_x . x_K + c_v . v_K with fixed N(0,1) vectors
(--seed); the gradient compared is the concatenation
[dL/dx0, dL/dv0, dL/dE, dL/dnu, dL/drho] (and every step's activations for a
scene with muscles). The reference is newton-cholesky with rel_tolerance
1e-10 and a direct adjoint. state_rel_error ([x; v] stacked),
position_rel_error (x), velocity_rel_error (v) and grad_rel_error
are relative 2-norms against it. forward_s / backward_s: wall-clock seconds of
Simulate / Backward on a fresh simulator (forward includes PD's factorisation,
factorization_s: the one-off cost per mesh, h and weights), median of --repeat runs. The adjoint tolerance is the
library's default (derived per step from the accuracy the forward reached)
unless --backward-rtol is given; the PD methods' adjoint solver is
--adjoint-solver (auto: per step by estimated cost). iter/dir: backward steps
solved iteratively / by a factorisation of the step Hessian.
speedup_vs_newton_cholesky = (forward+backward of newton-cholesky in this
run) / (this method's); speedup_vs_best_newton the same against the faster
of newton-cholesky and newton-pcg, speedup_vs_newton_ldlt against
newton-ldlt (the DiffPD paper's Newton: simplicial LDL^T under AMD).
JSON: a list of objects {method, status, forward_s, backward_s,
iters_per_step, state_rel_error, position_rel_error, velocity_rel_error,
grad_rel_error, grad_rel_error_by_input, forward_per_iteration_ms,
factorization_s, speedup_vs_newton_cholesky, speedup_vs_best_newton,
speedup_vs_newton_ldlt, backward_iters_per_step, backward_fallbacks,
backward_iterative_steps, backward_direct_steps, rounding_floor_steps (forward
steps ended at the rounding floor), newton_fallback_steps (PD-LBFGS steps
finished by Newton), problem, dofs, adjoint_solver, ...}.
--scaling: the problem at --scales x the elements (default 1,2,4,8); rows
{method, factor, elements, vertices, dofs, forward_s, iters_per_step,
forward_per_iteration_ms, factorization_s, iteration_ms, backward_per_step_ms,
backward_direct_steps, factor_copy_mib (the PD factor's copy for parallel
solves; 0: CHOLMOD solves, SolverOptions::pd_factor_copy_max_bytes),
peak_rss_mib, exponent_per_iteration, exponent_with_factorization}.
--cells NXxNYxNZ starts the cantilever from these cells instead of 32x8x8
(172x43x43: 334 928 vertices, 1.0 M DoFs). Methods
run to --rtol, so iteration counts differ per mesh: compare iteration_ms (the
forward without PD's one-off factorisation, per iteration);
exponent_per_iteration is its log-log slope against DoFs (1 = linear),
exponent_with_factorization that of forward_per_iteration_ms (the
factorisation spread over this run's iterations). peak_rss_mib is the
process's high-water mark.
--threads-compare: each method with 1 and 2 threads: forward seconds per step
(whole step), backward seconds, and the local step measured as one
Simulator::ElasticEnergy(x) evaluation, alternating between the last two
states (per-element SVD/projection work, the PD local step's cost), with
speed-ups 1-thread / 2-thread.)";

struct BenchArgs {
  std::string problem;
  std::vector<std::string> methods = {"pd", "pd-lbfgs", "newton-pcg", "newton-cholesky"};
  BenchOptions options;
  std::string adjoint_solver = ToString(SolverOptions().adjoint_solver);
  bool json = false;
  bool scaling = false;
  bool threads_compare = false;
  std::vector<int> scales = {1, 2, 4, 8};
  std::string cells;  // "" : the problem's own
};

void PrintBenchTable(const BenchResult& r) {
  std::printf("# %s: %d elements, %d DoFs, %d steps of %g s; reference newton-cholesky rtol 1e-10 (%.3f s)\n",
              r.problem.c_str(), r.elements, r.dofs, r.steps, r.time_step, r.reference_forward_s);
  std::printf("%-16s %10s %10s %10s %10s %12s %12s %9s %12s %10s %10s %12s %10s\n", "method", "forward_s", "backward_s",
              "factor_s", "iters/step", "ms/iter", "bwd_it/step", "iter/dir", "state_err", "x_err", "v_err", "grad_err",
              "speedup");
  for (const auto& row : r.rows) {
    if (!row.failure.empty()) {
      std::printf("%-16s failed: %s\n", row.method.c_str(), row.failure.c_str());
      continue;
    }
    const std::string split =
        std::to_string(row.backward_iterative_steps) + "/" + std::to_string(row.backward_direct_steps);
    std::printf("%-16s %10.4f %10.4f %10.4f %10.2f %12.4f %12.2f %9s %12.3e %10.2e %10.2e %12.3e", row.method.c_str(),
                row.forward_s, row.backward_s, row.factorization_s, row.iters_per_step, row.forward_per_iteration_ms,
                row.backward_iters_per_step, split.c_str(), row.state_rel_error, row.position_rel_error,
                row.velocity_rel_error, row.grad_rel_error);
    if (row.backward_fallbacks > 0) std::printf(" (%d adjoint fallbacks)", row.backward_fallbacks);
    if (row.rounding_floor_steps > 0) std::printf(" (%d steps at the rounding floor)", row.rounding_floor_steps);
    if (row.newton_fallback_steps > 0) std::printf(" (%d steps finished by Newton)", row.newton_fallback_steps);
    if (row.speedup_vs_newton_cholesky)
      std::printf(" %10.2f\n", *row.speedup_vs_newton_cholesky);
    else
      std::printf(" %10s\n", "-");
  }
}

void PrintScalingTable(const ScalingResult& r) {
  std::printf("%-16s %6s %9s %9s %10s %10s %10s %10s %12s %12s %12s %10s\n", "method", "factor", "elements", "dofs",
              "forward_s", "factor_s", "backward_s", "iters/step", "ms/iter", "iter_ms", "bwd_ms/step", "rss_MiB");
  for (const auto& row : r.rows) {
    if (!row.failure.empty()) {
      std::printf("%-16s %6d %9d %9d failed: %s\n", row.method.c_str(), row.factor, row.elements, row.dofs,
                  row.failure.c_str());
      continue;
    }
    std::printf("%-16s %6d %9d %9d %10.4f %10.4f %10.4f %10.2f %12.4f %12.4f %12.4f %10.1f\n", row.method.c_str(),
                row.factor, row.elements, row.dofs, row.forward_s, row.factorization_s, row.backward_s,
                row.iters_per_step, row.forward_per_iteration_ms, row.iteration_ms, row.backward_per_step_ms,
                row.peak_rss_mib);
  }
  for (const auto& [method, exponent] : r.exponent_per_iteration) {
    std::printf("# %s: time per iteration (iter_ms, without the one-off factorisation) ~ DoFs^%.2f", method.c_str(),
                exponent);
    const auto with = r.exponent_with_factorization.find(method);
    if (with != r.exponent_with_factorization.end()) std::printf("; with it (ms/iter) ~ DoFs^%.2f", with->second);
    std::printf("\n");
  }
}

void PrintThreadsTable(const std::vector<ThreadsRow>& rows) {
  std::printf("%-16s %12s %12s %8s %12s %12s %8s %12s %12s %8s\n", "method", "step_s(1)", "step_s(2)", "speedup",
              "bwd_s(1)", "bwd_s(2)", "speedup", "local_ms(1)", "local_ms(2)", "speedup");
  for (const auto& r : rows) {
    if (!r.failure.empty()) {
      std::printf("%-16s failed: %s\n", r.method.c_str(), r.failure.c_str());
      continue;
    }
    std::printf("%-16s %12.5f %12.5f %8.2f %12.4f %12.4f %8.2f %12.4f %12.4f %8.2f\n", r.method.c_str(), r.step_s_1,
                r.step_s_2, r.step_speedup(), r.backward_s_1, r.backward_s_2, r.backward_speedup(), r.local_ms_1,
                r.local_ms_2, r.local_speedup());
  }
}

int RunBenchArgs(const BenchArgs& args) {
  BenchOptions options = args.options;
  options.methods = ParseMethods(args.methods);
  options.adjoint_solver = ParseAdjointSolver(args.adjoint_solver);
  if (!args.cells.empty()) options.cantilever_cells = ParseCells(args.cells);
  if (args.scaling) {
    const ScalingResult r = RunScaling(args.problem, options, args.scales, &std::cerr);
    if (args.json)
      std::printf("%s\n", ScalingToJson(r).dump(2).c_str());
    else
      PrintScalingTable(r);
  } else if (args.threads_compare) {
    const auto rows = RunThreadsCompare(args.problem, options, 200, &std::cerr);
    if (args.json)
      std::printf("%s\n", ThreadsToJson(rows).dump(2).c_str());
    else
      PrintThreadsTable(rows);
  } else {
    const BenchResult r = RunBench(args.problem, options, &std::cerr);
    if (args.json)
      std::printf("%s\n", BenchToJson(r, options).dump(2).c_str());
    else
      PrintBenchTable(r);
  }
  return 0;
}

}  // namespace

Subcommand AddBenchCommand(CLI::App* parent) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = parent->add_subcommand(
      "bench", "forward/backward time, iterations and error vs. a converged Newton reference, per method");
  cmd->footer(kBenchFooter);
  cmd->add_option("problem", args->problem, "problem name (see `diffpd list`)")->required();
  cmd->add_option("--methods", args->methods,
                  "comma-separated methods: newton-cholesky, newton-pcg, newton-ldlt, pd, pd-lbfgs")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--adjoint-solver", args->adjoint_solver,
                  "PD methods' adjoint solver: auto (per step by estimated cost), iterative or direct")
      ->capture_default_str();
  cmd->add_option("--threads", args->options.threads, "threads for element loops (0: OpenMP default)")
      ->check(ThreadCount("--threads"));
  cmd->add_option("--repeat", args->options.repeat, "runs per method; times are medians")
      ->check(IntegerAtLeast("--repeat", 1))
      ->capture_default_str();
  cmd->add_option("--rtol", args->options.rel_tolerance, "relative tolerance of each step's solve")
      ->check(Fraction("--rtol"))
      ->capture_default_str();
  cmd->add_option("--backward-rtol", args->options.backward_rel_tolerance,
                  "relative tolerance of the adjoint solves (default: derived from the forward's accuracy)")
      ->check(Fraction("--backward-rtol"));
  cmd->add_option("--max-iterations", args->options.max_iterations, "iteration limit of each step's solve")
      ->check(IntegerAtLeast("--max-iterations", 1))
      ->capture_default_str();
  cmd->add_option("--lbfgs-scale", args->options.lbfgs_weight_scale,
                  "pd-lbfgs: elastic weight factor of its initial Hessian A, in (0, 1]")
      ->check(Fraction("--lbfgs-scale", true))
      ->capture_default_str();
  cmd->add_flag("--no-rigid-correction{false}", args->options.rigid_mode_correction,
                "pd-lbfgs and the PD backward: without the rigid modes' coarse correction");
  cmd->add_option("--steps", args->options.steps, "number of time steps (default: the problem's)")
      ->check(IntegerAtLeast("--steps", 1));
  cmd->add_option("--dt", args->options.time_step, "time step in seconds (default: the problem's)")
      ->check(Positive("--dt", "s"));
  cmd->add_option("--refine", args->options.refine,
                  "double the cells this many times (cycling x, y, z; negative halves); cantilever -9 = 4x1x1")
      ->check(IntegerIn("--refine", kMinRefinement, kMaxRefinement))
      ->capture_default_str();
  cmd->add_option("--cells", args->cells,
                  "cantilever: cells along x, y, z as NXxNYxNZ, before --refine's doublings (default 32x8x8)");
  cmd->add_option("--factor-copy-max-gib", args->options.factor_copy_max_gib,
                  "largest copy of the PD factor for parallel solves, GiB (default: the library's, 4; 0: none)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--seed", args->options.seed, "seed of the loss vectors")->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON document (a list) on stdout");
  CLI::Option* scaling =
      cmd->add_flag("--scaling", args->scaling, "time per iteration at --scales x the element count");
  CLI::Option* scales =
      cmd->add_option("--scales", args->scales, "comma-separated element-count factors, powers of 2 (with --scaling)")
          ->delimiter(',')
          ->capture_default_str();
  CLI::Option* threads =
      cmd->add_flag("--threads-compare", args->threads_compare, "1 vs 2 threads: whole step, backward and local step");
  scaling->excludes(threads);
  return {
      cmd, [args, scales] {
        // Without --scaling the bench would run with the scales ignored.
        if (scales->count() > 0 && !args->scaling)
          throw InvalidInputError("--scales is not used without --scaling (the element-count factors of --scaling)");
        return RunBenchArgs(*args);
      }};
}

}  // namespace diffpd::problems
