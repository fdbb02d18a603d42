// `diffpd tradeoff`: the command-line edge of tradeoff.h.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "tools/bench.h"
#include "cli/commands.h"
#include "cli/option_checks.h"
#include "diffpd/error.h"
#include "tools/tradeoff.h"

namespace diffpd::problems {
namespace {

constexpr const char* kTradeoffFooter = R"(
Time (forward + backward seconds) against error for each method, in three
sweeps, each against newton-cholesky converged to rel_tolerance 1e-10:
 tolerance  : rel_tolerance (forward and adjoint) = each --tolerances value;
              error of the final state [x_K, v_K] and of the gradient
              [dL/dx0, dL/dv0, dL/dE, dL/dnu, dL/drho] of L = c_x.x_K + c_v.v_K.
 time_step  : fixed duration T = steps * dt; h = dt / 2^k, k < --dt-levels,
              at --rtol; reference at dt / 2^dt-levels; same errors at T.
 resolution : the mesh with 3 j fewer doublings (half the cells per axis per
              level, --resolution-levels levels), at --rtol; reference on the
              finest mesh; errors of the final displacement of the 8 corner
              nodes and of (E dL/dE, nu dL/dnu, rho dL/drho), L linear in
              the corner positions.
JSON: a list of {sweep, method, parameter, value, seconds, state_rel_error,
grad_rel_error, status, forward_s, backward_s, iters_per_step, dofs, steps}.
--plot FILE.png: log-log plot (gnuplot), one curve per method, one column
per sweep, state error on top and gradient error below. The full cantilever
takes minutes per Newton run: use --steps (and --refine) to keep it short.)";

struct TradeoffArgs {
  std::string problem;
  std::vector<std::string> methods = {"pd", "pd-lbfgs", "newton-pcg", "newton-cholesky"};
  std::vector<std::string> sweeps = {"tolerance", "time_step", "resolution"};
  TradeoffOptions options;
  bool json = false;
  std::string plot;
};

int RunTradeoffArgs(const TradeoffArgs& args) {
  TradeoffOptions options = args.options;
  options.methods = ParseMethods(args.methods);
  options.sweep_tolerance = options.sweep_time_step = options.sweep_resolution = false;
  for (const auto& s : args.sweeps) {
    if (s == "tolerance")
      options.sweep_tolerance = true;
    else if (s == "time_step")
      options.sweep_time_step = true;
    else if (s == "resolution")
      options.sweep_resolution = true;
    else
      throw InvalidInputError("sweep '" + s + "' is invalid: valid sweeps are tolerance, time_step, resolution");
  }
  if (!args.plot.empty()) {
    // Fail before the (long) sweeps, not after.
    if (!GnuplotAvailable())
      throw std::runtime_error(
          "--plot needs the gnuplot program, which is not on PATH (Debian: apt-get install "
          "gnuplot-nox), or leave out --plot");
    const auto dir = std::filesystem::absolute(args.plot).parent_path();
    if (!std::filesystem::is_directory(dir))
      throw InvalidInputError("--plot " + args.plot + " is invalid: directory " + dir.string() + " does not exist");
  }
  const auto rows = RunTradeoff(args.problem, options, &std::cerr);
  if (!args.plot.empty()) {
    WriteTradeoffPlot(rows, args.plot, "diffpd tradeoff: " + args.problem);
    std::cerr << "[tradeoff] wrote " << args.plot << std::endl;
  }
  if (args.json) {
    std::printf("%s\n", TradeoffToJson(rows).dump(2).c_str());
    return 0;
  }
  std::printf("%-11s %-16s %-14s %12s %10s %12s %12s %10s\n", "sweep", "method", "parameter", "value", "seconds",
              "state_err", "grad_err", "iters/step");
  for (const auto& r : rows) {
    if (!r.failure.empty()) {
      std::printf("%-11s %-16s %-14s %12.4g failed: %s\n", r.sweep.c_str(), r.method.c_str(), r.parameter.c_str(),
                  r.value, r.failure.c_str());
      continue;
    }
    std::printf("%-11s %-16s %-14s %12.4g %10.4f %12.3e %12.3e %10.2f\n", r.sweep.c_str(), r.method.c_str(),
                r.parameter.c_str(), r.value, r.seconds, r.state_rel_error, r.grad_rel_error, r.iters_per_step);
  }
  return 0;
}

}  // namespace

Subcommand AddTradeoffCommand(CLI::App* parent) {
  auto args = std::make_shared<TradeoffArgs>();
  CLI::App* cmd = parent->add_subcommand(
      "tradeoff", "time vs. error per method, sweeping tolerance, time step and mesh resolution");
  cmd->footer(kTradeoffFooter);
  TradeoffOptions& o = args->options;
  cmd->add_option("problem", args->problem, "problem name: cantilever or falling-cube")->required();
  cmd->add_option("--methods", args->methods, "comma-separated methods: newton-cholesky, newton-pcg, pd, pd-lbfgs")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sweeps", args->sweeps, "comma-separated sweeps: tolerance, time_step, resolution")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--tolerances", o.tolerances, "comma-separated tolerances of the tolerance sweep")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--rtol", o.rel_tolerance, "tolerance of the time-step and resolution sweeps")
      ->check(Fraction("--rtol"))
      ->capture_default_str();
  cmd->add_option("--max-iterations", o.max_iterations, "iteration limit of each step's solve")
      ->check(IntegerAtLeast("--max-iterations", 1))
      ->capture_default_str();
  cmd->add_option("--steps", o.steps, "number of time steps at --dt (default: the problem's)")
      ->check(IntegerAtLeast("--steps", 1));
  cmd->add_option("--dt", o.time_step, "coarsest time step in seconds (default: the problem's)")
      ->check(Positive("--dt", "s"));
  cmd->add_option("--dt-levels", o.time_step_levels, "time steps dt / 2^k, k < dt-levels")
      ->check(IntegerAtLeast("--dt-levels", 1))
      ->capture_default_str();
  cmd->add_option("--resolution-levels", o.resolution_levels, "meshes, each halving the cells per axis")
      ->check(IntegerAtLeast("--resolution-levels", 1))
      ->capture_default_str();
  cmd->add_option("--refine", o.refine, "cell doublings of the (finest) mesh; cantilever -9 = 4x1x1")
      ->check(IntegerIn("--refine", kMinRefinement, kMaxRefinement))
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "threads for element loops (0: OpenMP default)")
      ->check(ThreadCount("--threads"));
  cmd->add_option("--seed", o.seed, "seed of the loss vectors")->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON document (a list) on stdout");
  cmd->add_option("--plot", args->plot, "write a log-log PNG of time vs. error (needs gnuplot)");
  return {cmd, [args] { return RunTradeoffArgs(*args); }};
}

}  // namespace diffpd::problems
