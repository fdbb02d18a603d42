// The subcommands of the diffpd program. Each returns the process exit code;
// with json = true stdout carries exactly one JSON document and everything
// else goes to stderr.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "diffpd/solver_options.h"
#include "tools/gradcheck.h"

namespace CLI {
class App;
}

namespace diffpd::problems {

class Problem;  // problem.h

// Settings shared by the subcommands that simulate a problem.
struct CommandArgs {
  std::string problem;
  Method method = Method::kPd;
  int threads = 0;
  int steps = -1;                                                      // -1: the problem's default
  double dt = -1;                                                      // -1: the problem's default (s)
  double rel_tolerance = -1;                                           // -1: the command's default
  double lbfgs_weight_scale = SolverOptions().lbfgs_weight_scale;      // pd-lbfgs preconditioner
  bool rigid_mode_correction = SolverOptions().rigid_mode_correction;  // pd-lbfgs, PD backward
  int verbosity = 0;    // SolverOptions::verbosity: 0 silent, 1 per step, 2 per iteration
  std::string out_dir;  // "" : no files
  bool json = false;
  // Optimisation problems (Problem::Run): the reduced instance, whether to
  // repeat the solve with newton-cholesky for the time ratio, and Ipopt
  // options as "name=value" (int, number or string, passed unchanged).
  bool small = false;
  bool compare_newton = true;
  std::vector<std::string> ipopt_options;
  // Control problems (starfish-control, shark-control): training
  // evaluations (-1: the problem's; at most kMaxEvaluations) and the
  // network's seed (-1: the problem's; at most kMaxSeed).
  static constexpr int kMaxEvaluations = 100000;
  static constexpr long kMaxSeed = 2147483647;
  int evaluations = -1;
  long long seed = -1;
  std::string optimizer;  // "": adam; adam, lbfgs or ipopt
  // Calibration problems (calibrate-*): the captured-motion file (default:
  // the problem's file in data/), the methods to fit with and compare
  // (default: the problem's), a cap on Ceres iterations (-1: the problem's);
  // calibrate-starfish: the recording to fit, those to predict, the
  // seconds of each recording to evaluate (-1: the problem's default) and
  // the material regions ("": one material; "body-arms": separate E for the
  // central body and the four arms), the fit ("": the problem's; "lm",
  // "lbfgs") and its window (start and length, s; -1: the problem's).
  std::string data_file;
  std::vector<std::string> methods;
  int max_iterations = -1;
  std::string calibrate_file;
  std::vector<std::string> predict_files;
  double seconds = -1;
  std::string regions;
  std::string fit;
  double fit_start = -1;
  double fit_seconds = -1;
  std::string water;    // calibrate-starfish: "": the problem's; "fitted", "fixed"
  std::string servo;    // calibrate-starfish: "": the problem's; "symmetric", "asymmetric"
  int starts = -1;      // calibrate-starfish: fits from this many starting points (-1: the problem's)
  std::string density;  // calibrate-starfish: "": the problem's; "fitted", "fixed"
  std::string damping;  // calibrate-starfish: "": the problem's; "fitted", "fixed"
};

int ListCommand(bool json);
int RunCommand(const CommandArgs& args);
// `diffpd gradcheck`: the check's own options in `check`; --rtol defaults to
// RecommendedGradCheckRelTolerance(method), the iteration limit is
// RecommendedGradCheckMaxIterations(method). Exit code 4 when an input fails.
int GradcheckCommand(const CommandArgs& args, const GradCheckOptions& check);

// A subcommand that declares its own options: `app` is the CLI11 subcommand
// (true once parsed), `run` runs it after parsing.
struct Subcommand {
  CLI::App* app = nullptr;
  std::function<int()> run;
};
Subcommand AddBenchCommand(CLI::App* parent);     // bench_command.cc
Subcommand AddTradeoffCommand(CLI::App* parent);  // tradeoff_command.cc
Subcommand AddStressCommand(CLI::App* parent);    // stress_command.cc
Subcommand AddSynthCommand(CLI::App* parent);     // synth_command.cc
// `argv`: the program's whole command line, stored in the table's result.
Subcommand AddTableCommand(CLI::App* parent, const std::vector<std::string>& argv);  // table_command.cc

// `diffpd run`'s options that only some kinds of problem read (--small,
// --no-compare, --ipopt: optimisation; --evaluations, --seed, --optimizer: control
// (--small, --no-compare too); --data, --methods, --max-iterations:
// calibration; --calibrate, --predict, --seconds, --regions: the starfish):
// throws InvalidInputError for one given to a problem that would ignore it,
// "--ipopt is not used by the simulation problem 'cantilever' (only the
// optimisation problems read it)".
void RefuseUnusedRunOptions(const CommandArgs& args, const Problem& problem);

// Calibration problems fit with the library's PD-LBFGS settings and a silent
// simulator: throws InvalidInputError if --lbfgs-scale, --no-rigid-correction
// or a non-zero --verbosity was given.
void RefuseSimulatorTuning(const CommandArgs& args, const std::string& problem);

// Solver options for a problem from the shared arguments.
SolverOptions OptionsFromArgs(const CommandArgs& args, double default_dt, double default_rel_tolerance);

}  // namespace diffpd::problems
