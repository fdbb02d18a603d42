// `diffpd stress`: the command-line edge of stress.h.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "tools/bench.h"
#include "cli/commands.h"
#include "cli/option_checks.h"
#include "tools/stress.h"

namespace diffpd::problems {
namespace {

constexpr const char* kStressFooter = R"(
Runs every (problem, method, E, nu, dt) case for --steps steps and, with
--long-steps K, each problem and method at the grid's extreme corners for K
steps (the long cases: (E, nu, dt) = (min, min, max), (min, max, min),
(max, min, min), (max, max, max); --long-only: these alone), and
classifies every case:
 ok        : finite states; total energy (kinetic + elastic + gravitational
             potential) never above its start by more than --energy-tol
             relative (scenes with frictional contact: --contact-energy-tol;
             semi-implicit, which does not dissipate: 0.5, i.e.
             not exploding); finite gradients from the backward pass of the whole
             rollout; on the first --gradcheck-steps steps (long cases: the
             last ones, from the state reached there) the gradient check
             (as `diffpd gradcheck`: solves at --gradcheck-rtol, a noise floor
             and verdict per input, the Newton-Cholesky reference for the
             iterative methods) passes within --gradcheck-tol or leaves the
             input unresolved (listed with the case);
 failed    : a SolverError stopped the case: its status and message;
 violation : a non-finite result without an error, energy growth, a gradient
             check that fails or an unexpected error - a library bug.
Exit code 4 when any case is a violation. JSON: a list of {problem, method,
youngs_modulus, poissons_ratio, time_step, steps, long_case, outcome,
message, steps_completed, rounding_floor_steps, newton_fallback_steps,
contact_steps, max_contact_nodes, max_energy_excess,
gradcheck_run, gradcheck_error, gradcheck_floor, gradcheck_margin,
gradcheck_unresolved, gradcheck_tangent, gradcheck_tightened, gradcheck_reference,
gradcheck_reference_failure, seconds}; the error is on each
input's basis (the differences, or the forward-mode tangent where the
differences could not decide: gradcheck_tangent), the margin tolerance /
max(error, floor) over the resolved inputs; gradcheck_tightened lists the
inputs that passed although the Newton-Cholesky reference disagreed,
because the method's gradient with its forward 100x tighter agrees with it.
The table ends with the number
of cases with unresolved inputs and the smallest margin.
Solves stop at |grad g| <= --abs-tol + --rtol |grad g(x0)|; by default
--abs-tol is 10x an estimate of the rounding floor of |grad g| (never below
1e-9 N), which grows with stiffness and 1/dt^2. Steps whose line search
stalls at the library's own floor estimate end there (rounding_floor_steps;
SolverOptions::accept_rounding_floor), and PD-LBFGS steps whose line search
stalls above it are finished by Newton (newton_fallback_steps).
Meshes: --refine doublings of each problem's cells (-6: cantilever 8x2x2,
falling cube 2x2x2, bouncing ball 8 voxels, rolling sphere 19; -9:
cantilever 4x1x1, one cell of the others). The contact scenes (bouncing-ball,
rolling-sphere) keep their frictional ground contact at every E, nu and dt;
contact_steps counts the steps that ended with nodes in contact.)";

struct StressArgs {
  std::vector<std::string> problems = {"cantilever", "falling-cube"};
  std::vector<std::string> methods = {"pd", "pd-lbfgs", "newton-pcg", "newton-cholesky"};
  int refine = -6;
  StressOptions options;
  bool json = false;
};

int RunStressArgs(const StressArgs& args) {
  StressOptions options = args.options;
  options.methods = ParseMethods(args.methods);
  options.problems.clear();
  for (const auto& p : args.problems) options.problems.push_back({p, args.refine});
  const auto cases = RunStress(options, &std::cerr);
  const StressSummary summary = SummarizeStress(cases);
  if (args.json) {
    std::printf("%s\n", StressToJson(cases).dump(2).c_str());
  } else {
    std::printf("%-13s %-16s %8s %6s %8s %-10s %7s %11s %11s %9s %9s  %s\n", "problem", "method", "E", "nu", "dt",
                "outcome", "steps", "energy_exc", "gradcheck", "margin", "seconds", "message");
    for (const auto& c : cases) {
      std::string message = c.message;
      if (c.rounding_floor_steps > 0 || c.newton_fallback_steps > 0) {
        message += message.empty() ? "" : "; ";
        message += std::to_string(c.rounding_floor_steps) + " steps at the rounding floor, " +
                   std::to_string(c.newton_fallback_steps) + " finished by Newton";
      }
      if (c.contact_steps > 0) {
        message += message.empty() ? "" : "; ";
        message += "contact in " + std::to_string(c.contact_steps) + " steps (up to " +
                   std::to_string(c.max_contact_nodes) + " nodes)";
      }
      if (!c.gradcheck_tangent.empty()) {
        message += message.empty() ? "" : "; ";
        message += "decided by the tangent:";
        for (const auto& input : c.gradcheck_tangent) message += " " + input;
      }
      if (!c.gradcheck_tightened.empty()) {
        message += message.empty() ? "" : "; ";
        message += "agree with the reference at a 100x tighter forward:";
        for (const auto& input : c.gradcheck_tightened) message += " " + input;
      }
      if (!c.gradcheck_unresolved.empty()) {
        message += message.empty() ? "" : "; ";
        message += "gradient unresolved:";
        for (const auto& input : c.gradcheck_unresolved) message += " " + input;
      }
      std::printf("%-13s %-16s %8.0e %6.3g %8.0e %-10s %7d %11.2e %11.2e %9.3g %9.3f  %s\n", c.problem.c_str(),
                  c.method.c_str(), c.youngs_modulus, c.poissons_ratio, c.time_step, c.outcome.c_str(),
                  c.steps_completed, c.max_energy_excess, c.gradcheck_error, c.gradcheck_margin, c.seconds,
                  message.c_str());
    }
    std::printf("# %d cases: %d ok, %d failed with a solver error, %d violations (%d long, %d with contact)\n",
                summary.cases, summary.ok, summary.failed, summary.violations, summary.long_cases,
                summary.contact_cases);
    std::printf(
        "# gradient checks: %d run, %d with unresolved inputs, %d with inputs decided by the tangent, smallest margin "
        "of a resolved input %.3g\n",
        summary.gradchecks, summary.unresolved_cases, summary.tangent_cases, summary.min_gradcheck_margin);
  }
  if (summary.violations > 0) {
    std::fprintf(stderr, "diffpd stress: %d case(s) violated the stability contract (see the table)\n",
                 summary.violations);
    return 4;
  }
  return 0;
}

}  // namespace

Subcommand AddStressCommand(CLI::App* parent) {
  auto args = std::make_shared<StressArgs>();
  CLI::App* cmd = parent->add_subcommand(
      "stress", "stability at the extremes of E, nu and dt: each case ok or a clear solver error, never NaN");
  cmd->footer(kStressFooter);
  StressOptions& o = args->options;
  cmd->add_option("--problems", args->problems,
                  "comma-separated problems: cantilever, falling-cube, bouncing-ball, rolling-sphere")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--methods", args->methods,
                  "comma-separated methods: semi-implicit, newton-cholesky, newton-pcg, pd, pd-lbfgs")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--refine", args->refine, "cell doublings of every problem's mesh")
      ->check(IntegerIn("--refine", kMinRefinement, kMaxRefinement))
      ->capture_default_str();
  cmd->add_option("--E", o.youngs_moduli, "comma-separated Young's moduli (Pa)")
      ->delimiter(',')
      ->check(Positive("--E", "Pa"))
      ->capture_default_str();
  cmd->add_option("--nu", o.poissons_ratios, "comma-separated Poisson's ratios")
      ->delimiter(',')
      ->check(OpenInterval("--nu", -1, 0.5))
      ->capture_default_str();
  cmd->add_option("--dt", o.time_steps, "comma-separated time steps (s)")
      ->delimiter(',')
      ->check(Positive("--dt", "s"))
      ->capture_default_str();
  cmd->add_option("--steps", o.steps, "steps per case")->check(IntegerAtLeast("--steps", 1))->capture_default_str();
  cmd->add_option("--rtol", o.rel_tolerance, "relative tolerance of each step's solve")
      ->check(Fraction("--rtol"))
      ->capture_default_str();
  cmd->add_option("--abs-tol", o.abs_tolerance, "absolute tolerance of each step's solve (N; default: automatic)")
      ->check(Positive("--abs-tol", "N"));
  cmd->add_option("--max-iterations", o.max_iterations, "iteration limit of each step's solve")
      ->check(IntegerAtLeast("--max-iterations", 1))
      ->capture_default_str();
  cmd->add_option("--threads", o.threads, "threads for element loops (0: OpenMP default)")
      ->check(ThreadCount("--threads"));
  cmd->add_option("--energy-tol", o.energy_tolerance, "allowed relative rise of the total energy")
      ->check(NonNegative("--energy-tol"))
      ->capture_default_str();
  cmd->add_option("--contact-energy-tol", o.contact_energy_tolerance, "the same for scenes with frictional contact")
      ->check(NonNegative("--contact-energy-tol"))
      ->capture_default_str();
  cmd->add_option("--long-steps", o.long_steps, "steps of the long cases at the grid's extreme corners (0: none)")
      ->check(IntegerAtLeast("--long-steps", 0))
      ->capture_default_str();
  cmd->add_flag("--long-only", o.long_only, "run only the long cases (needs --long-steps)");
  cmd->add_option("--gradcheck-steps", o.gradcheck_steps, "steps of the finite-difference check (0: skip)")
      ->check(IntegerAtLeast("--gradcheck-steps", 0))
      ->capture_default_str();
  cmd->add_option("--gradcheck-tol", o.gradcheck_tolerance, "allowed relative error of the gradient check")
      ->check(Positive("--gradcheck-tol"))
      ->capture_default_str();
  cmd->add_option("--gradcheck-rtol", o.gradcheck_rel_tolerance, "relative tolerance of the gradient check's solves")
      ->check(Fraction("--gradcheck-rtol"))
      ->capture_default_str();
  cmd->add_option("--seed", o.seed, "seed of the loss and check directions")->capture_default_str();
  cmd->add_flag("--no-rigid-correction{false}", o.rigid_mode_correction,
                "pd-lbfgs and the PD backward: without the rigid modes' coarse correction");
  cmd->add_flag("--json", args->json, "print one JSON document (a list) on stdout");
  return {cmd, [args] { return RunStressArgs(*args); }};
}

}  // namespace diffpd::problems
