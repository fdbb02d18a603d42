// diffpd: command-line front end of the DiffPD library.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <string>

#include "cli/commands.h"
#include "problem_registry.h"
#include "diffpd/error.h"

namespace {

using diffpd::problems::CommandArgs;

// Adds the options shared by the simulating subcommands.
void AddCommonOptions(CLI::App* cmd, CommandArgs* args, std::string* method) {
  cmd->add_option("problem", args->problem, "problem name (see `diffpd list`)")->required();
  cmd->add_option("--method", *method, "semi-implicit, newton-cholesky, newton-pcg, pd or pd-lbfgs")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads, "threads for element loops (0: OpenMP default)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--steps", args->steps, "number of time steps (default: the problem's)");
  cmd->add_option("--dt", args->dt, "time step in seconds (default: the problem's)");
  cmd->add_option("--rtol", args->rel_tolerance, "relative tolerance on |grad g| per step");
  cmd->add_option("--lbfgs-scale", args->lbfgs_weight_scale,
                  "pd-lbfgs: elastic weight factor of its initial Hessian A, in (0, 1]")
      ->capture_default_str();
  cmd->add_flag("--no-rigid-correction{false}", args->rigid_mode_correction,
                "pd-lbfgs and the PD backward: without the rigid modes' coarse correction");
  cmd->add_option("--verbosity", args->verbosity,
                  "solver log on stderr: 0 none, 1 a line per step, 2 a line per iteration and contact pass")
      ->check(CLI::Range(0, 2))
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON document on stdout");
}

}  // namespace

int main(int argc, char** argv) {
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
  run->add_option("--data", run_args.data_file,
                  "calibration problems: captured-motion CSV (default: the problem's in data/)");
  run->add_option("--methods", run_args.methods,
                  "calibration problems: methods to fit with, compared (comma-separated)")
      ->delimiter(',');
  run->add_option("--max-iterations", run_args.max_iterations, "calibration problems: Ceres iterations per fit");
  run->add_option("--calibrate", run_args.calibrate_file, "calibrate-starfish: the recording to fit");
  run->add_option("--predict", run_args.predict_files, "calibrate-starfish: recordings to predict (repeatable)");
  run->add_option("--seconds", run_args.seconds, "calibrate-starfish: seconds of each recording to evaluate");
  run->add_option("--regions", run_args.regions,
                  "calibrate-starfish: material regions, 'body-arms' (separate E for the body and the arms)");
  run->add_option("--fit", run_args.fit,
                  "calibrate-starfish: 'lm' (Levenberg-Marquardt on marker residuals, default) or 'lbfgs'");
  run->add_option("--fit-start", run_args.fit_start, "calibrate-starfish: start of the fit window (s, default 1)");
  run->add_option("--fit-seconds", run_args.fit_seconds, "calibrate-starfish: length of the fit window (s, default 2)");

  CLI::App* grad = app.add_subcommand("gradcheck", "compare rollout gradients with central finite differences");
  AddCommonOptions(grad, &grad_args, &grad_method);
  const auto bench = diffpd::problems::AddBenchCommand(&app);
  const auto tradeoff = diffpd::problems::AddTradeoffCommand(&app);
  const auto stress = diffpd::problems::AddStressCommand(&app);
  const auto synth = diffpd::problems::AddSynthCommand(&app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*list) return diffpd::problems::ListCommand(list_json);
    if (*run) {
      run_args.method = diffpd::ParseMethod(run_method);
      const int own = diffpd::problems::MakeProblem(run_args.problem)->Run(run_args);
      if (own >= 0) return own;
      return diffpd::problems::RunCommand(run_args);
    }
    if (*grad) {
      grad_args.method = diffpd::ParseMethod(grad_method);
      return diffpd::problems::GradcheckCommand(grad_args);
    }
    if (*bench.app) return bench.run();
    if (*tradeoff.app) return tradeoff.run();
    if (*stress.app) return stress.run();
    if (*synth.app) return synth.run();
  } catch (const diffpd::InvalidInputError& e) {
    std::fprintf(stderr, "diffpd: invalid input: %s\n", e.what());
    return 2;
  } catch (const diffpd::SolverError& e) {
    std::fprintf(stderr, "diffpd: solver failed (%s): %s\n", diffpd::ToString(e.status()), e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "diffpd: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
