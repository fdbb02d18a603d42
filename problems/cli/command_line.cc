// RunCommandLine (command_line.h): the diffpd program's subcommands, their
// options and the mapping of exceptions to exit statuses.
#include "cli/command_line.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/option_checks.h"
#include "diffpd/error.h"
#include "problem_registry.h"

namespace diffpd::problems {
namespace {

// Adds the options shared by the simulating subcommands.
void AddCommonOptions(CLI::App* cmd, CommandArgs* args, std::string* method) {
  cmd->add_option("problem", args->problem, "problem name (see `diffpd list`)")->required();
  cmd->add_option("--method", *method, "semi-implicit, newton-cholesky, newton-pcg, newton-ldlt, pd or pd-lbfgs")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "threads for element loops (0: OpenMP default)")
      ->check(ThreadCount("--threads"));
  cmd->add_option("--steps", args->steps, "number of time steps (default: the problem's)")
      ->check(IntegerAtLeast("--steps", 1));
  cmd->add_option("--dt", args->dt, "time step in seconds (default: the problem's)")->check(Positive("--dt", "s"));
  cmd->add_option("--rtol", args->rel_tolerance, "relative tolerance on |grad g| per step")->check(Fraction("--rtol"));
  cmd->add_option("--lbfgs-scale", args->lbfgs_weight_scale,
                  "pd-lbfgs: elastic weight factor of its initial Hessian A, in (0, 1]")
      ->check(Fraction("--lbfgs-scale", true))
      ->capture_default_str();
  cmd->add_flag("--no-rigid-correction{false}", args->rigid_mode_correction,
                "pd-lbfgs and the PD backward: without the rigid modes' coarse correction");
  cmd->add_option("--verbosity", args->verbosity,
                  "solver log on stderr: 0 none, 1 a line per step, 2 a line per iteration and contact pass")
      ->check(IntegerIn("--verbosity", 0, 2))
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON document on stdout");
}

}  // namespace

int RunCommandLine(const std::vector<std::string>& argv) {
  CLI::App app{"diffpd: differentiable soft-body simulation by projective dynamics"};
  app.require_subcommand(1);
  bool list_json = false;
  CLI::App* list = app.add_subcommand("list", "list the problems with a one-line description");
  list->add_flag("--json", list_json, "print a JSON list");

  CommandArgs run_args, grad_args;
  std::string run_method = "pd-lbfgs", grad_method = "pd";  // pd-lbfgs: the fastest PD variant measured on every scene
  CLI::App* run = app.add_subcommand("run", "simulate a problem, print a per-step table and write results");
  AddCommonOptions(run, &run_args, &run_method);
  run->add_option(
      "--out", run_args.out_dir,
      "directory for VTK frames (.vtu + .pvd), plots and summary.json (optimisation problems: default out/<problem>)");
  run->add_flag("--small", run_args.small, "optimisation problems: the reduced instance (under a minute)");
  run->add_flag("!--no-compare", run_args.compare_newton,
                "optimisation problems: skip the repeat with newton-cholesky");
  run->add_option("--ipopt", run_args.ipopt_options, "optimisation problems: Ipopt option name=value (repeatable)");
  run->add_option("--evaluations", run_args.evaluations,
                  "control problems: training evaluations (rollouts; default 100, --small fewer)")
      ->check(IntegerIn("--evaluations", 1, CommandArgs::kMaxEvaluations));
  run->add_option("--seed", run_args.seed, "control problems: seed of the network's initial weights (default 42)")
      ->check(IntegerIn("--seed", 0, CommandArgs::kMaxSeed));
  run->add_option(
      "--optimizer", run_args.optimizer,
      "control problems: adam (the original's settings), lbfgs (Ceres), ipopt (limited-memory Hessian) or all");
  run->add_option("--data", run_args.data_file,
                  "calibration problems: captured-motion CSV (default: the problem's in data/)");
  run->add_option("--methods", run_args.methods,
                  "calibration problems: methods to fit with, compared (comma-separated)")
      ->delimiter(',');
  run->add_option("--max-iterations", run_args.max_iterations, "calibration problems: Ceres iterations per fit")
      ->check(IntegerAtLeast("--max-iterations", 1));
  run->add_option("--calibrate", run_args.calibrate_file, "calibrate-starfish: the recording to fit");
  run->add_option("--predict", run_args.predict_files, "calibrate-starfish: recordings to predict (repeatable)");
  run->add_option("--seconds", run_args.seconds, "calibrate-starfish: seconds of each recording to evaluate")
      ->check(Positive("--seconds", "s"));
  run->add_option("--regions", run_args.regions,
                  "calibrate-starfish: material regions, 'body-arms' (separate E for the body and the arms)");
  run->add_option("--fit", run_args.fit,
                  "calibrate-starfish: 'lm' (Levenberg-Marquardt on marker residuals, default) or 'lbfgs'");
  run->add_option("--fit-start", run_args.fit_start, "calibrate-starfish: start of the fit window (s, default 1)")
      ->check(NonNegative("--fit-start"));
  run->add_option("--water", run_args.water,
                  "calibrate-starfish: 'fitted' (the lm fit fits drag and thrust, default) or 'fixed'");
  run->add_option(
      "--servo", run_args.servo,
      "calibrate-starfish: 'asymmetric' fits a release lag apart from the pull's (lm fit, default), or 'symmetric'");
  run->add_option("--fit-seconds", run_args.fit_seconds, "calibrate-starfish: length of the fit window (s, default 5)")
      ->check(Positive("--fit-seconds", "s"));
  run->add_option("--starts", run_args.starts,
                  "calibrate-starfish: fit from this many starting points (1 to 4, default 1), keep the fit with the "
                  "lowest cost on the calibration window")
      ->check(IntegerIn("--starts", 1, 4));
  run->add_option(
      "--density", run_args.density,
      "calibrate-starfish: 'fitted' (default: the lm fit fits the body's density) or 'fixed' (the scene's 400 kg/m^3)");
  run->add_option("--damping", run_args.damping,
                  "calibrate-starfish: 'fitted' (the lm fit fits a linear damping) or 'fixed' (default: none)");

  CLI::App* grad = app.add_subcommand("gradcheck", "compare rollout gradients with central finite differences");
  AddCommonOptions(grad, &grad_args, &grad_method);
  GradCheckOptions grad_check;
  grad->add_option("--tol", grad_check.tolerance, "relative tolerance of every verdict")
      ->check(Positive("--tol"))
      ->capture_default_str();
  grad->add_option("--directions", grad_check.directions, "random directions per input kind")
      ->check(IntegerAtLeast("--directions", 1))
      ->capture_default_str();
  grad->add_option("--early-stop", grad_check.early_stop_margin,
                   "stop at three steps per direction where they pass with this margin (0: always six)")
      ->check(ZeroOrAtLeast("--early-stop", 1))
      ->capture_default_str();
  grad->add_option("--concurrent-rollouts", grad_check.concurrent_rollouts,
                   "perturbed rollouts simulated at once, each on one thread (the result is the same)")
      ->check(IntegerIn("--concurrent-rollouts", 1, MaxSolverThreads()))
      ->capture_default_str();
  bool grad_reference = false, grad_no_reference = false;
  grad->add_flag("--reference", grad_reference,
                 "also compare with a tightly converged Newton-Cholesky rollout's gradient (default for pd, pd-lbfgs, "
                 "newton-pcg)");
  grad->add_flag("--no-reference", grad_no_reference, "never compare with the Newton-Cholesky reference");
  grad->footer(R"(
Per input kind (x0, v0, external_force, activation, material and force
parameters): the relative error of the gradient against central differences,
the noise floor of the differences (from the forward's achieved residuals and
from differences at several steps), the margin tolerance / max(error, floor)
and a verdict: pass, fail, or unresolved (the differences cannot resolve the
derivative to the tolerance; the reason gives the floor). Three steps per
direction suffice where they pass with the --early-stop margin; otherwise
six are taken, and two wider ones where still unresolved or passing with a
margin below 10 (kept where they pass with a larger one). Where the
differences do not pass with a margin of 3, the forward-mode tangent of the
same states (the tangent column) decides; the basis column says which did.
For the iterative methods the gradient is also compared with a
Newton-Cholesky rollout's at rel_tolerance 1e-12 (the reference column).
The solves run at --rtol (default 1e-11; pd 1e-10 with up to 10000
iterations per step; a method that does not reach it is checked at the
tightest of 100x, 10^4x, ... up to 1e-6 it reaches, and says so), the
perturbed rollouts one at a time unless
--concurrent-rollouts says more. Semi-implicit runs at the problem's step,
or at half its stability limit at the initial state where the problem's step
is above that (and says so); --dt sets the step for every method. A line on
stderr reports each direction as it is judged. Exit code 4 when an input
fails.)");
  const auto bench = AddBenchCommand(&app);
  const auto tradeoff = AddTradeoffCommand(&app);
  const auto stress = AddStressCommand(&app);
  const auto synth = AddSynthCommand(&app);
  const auto table = AddTableCommand(&app, argv);

  try {
    // CLI11 wants argv in reverse order, without the program name.
    std::vector<std::string> arguments(argv.rbegin(), argv.rend());
    if (!arguments.empty()) arguments.pop_back();
    try {
      app.parse(arguments);
    } catch (const CLI::ParseError& e) {
      return app.exit(e);
    }
    if (*list) return ListCommand(list_json);
    if (*run) {
      run_args.method = ParseMethod(run_method);
      const std::unique_ptr<Problem> problem = MakeProblem(run_args.problem);
      RefuseUnusedRunOptions(run_args, *problem);
      const int own = problem->Run(run_args);
      if (own >= 0) return own;
      return RunCommand(run_args);
    }
    if (*grad) {
      grad_args.method = ParseMethod(grad_method);
      if (grad_reference && grad_no_reference)
        throw InvalidInputError("--reference and --no-reference exclude each other: give one");
      if (grad_reference) grad_check.reference = true;
      if (grad_no_reference) grad_check.reference = false;
      return GradcheckCommand(grad_args, grad_check);
    }
    if (*bench.app) return bench.run();
    if (*tradeoff.app) return tradeoff.run();
    if (*stress.app) return stress.run();
    if (*synth.app) return synth.run();
    if (*table.app) return table.run();
  } catch (const InvalidInputError& e) {
    std::fprintf(stderr, "diffpd: invalid input: %s\n", e.what());
    return 2;
  } catch (const SolverError& e) {
    std::fprintf(stderr, "diffpd: solver failed (%s): %s\n", ToString(e.status()), e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "diffpd: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace diffpd::problems
