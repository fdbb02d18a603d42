// The diffpd program's command line (cli/command_line.h), run in-process:
// every out-of-range option value, every option the chosen problem would
// ignore and every unreadable input is refused with the project's message
// and exit status 2, before anything is simulated. One row per command line.
#include "cli/command_line.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "diffpd/solver_options.h"
#include "problem_registry.h"
#include "tools/problem_objective.h"
#include "util/temporary_directory.h"

namespace diffpd::problems {
namespace {

std::string TempPath(const std::string& name) {
  static const testing::TemporaryDirectory directory("diffpd-command-line");
  return directory.File(name);
}

std::string WriteTemp(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  std::ofstream(path) << text;
  return path;
}

// A command line (after "diffpd"), and the exit status and exact stderr expected.
struct Refusal {
  std::vector<std::string> args;
  int status;
  std::string error;
};

// Whether this diffpd has the problem (the calibration and optimisation
// problems come with their adapters).
bool Registered(const std::string& name) {
  for (const auto& p : AllProblems())
    if (p->name() == name) return true;
  return false;
}

void ExpectRefusals(const std::vector<Refusal>& refusals) {
  for (const Refusal& r : refusals) {
    const bool refuses_the_name = r.error.find("unknown problem") != std::string::npos;
    if (r.args.size() >= 2 && r.args[0] == "run" && !refuses_the_name && !Registered(r.args[1])) continue;
    std::vector<std::string> argv = {"diffpd"};
    argv.insert(argv.end(), r.args.begin(), r.args.end());
    std::string line;
    for (const std::string& a : r.args) line += " " + a;
    ::testing::internal::CaptureStderr();
    ::testing::internal::CaptureStdout();
    const int status = RunCommandLine(argv);
    ::testing::internal::GetCapturedStdout();
    const std::string error = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(status, r.status) << "diffpd" << line;
    EXPECT_EQ(error, r.error) << "diffpd" << line;
  }
}

std::string Invalid(const std::string& message) { return "diffpd: invalid input: " + message + "\n"; }

// ObjectiveProblemNames() as the trade-off's message lists them.
std::string TradeoffProblems() {
  std::string out;
  for (const auto& n : ObjectiveProblemNames()) out += (out.empty() ? "" : ", ") + n;
  return out;
}

TEST(CommandLineTest, RefusesOutOfRangeValuesOfTheSimulatingCommands) {
  const std::string threads = "must be an integer in [0, " + std::to_string(MaxSolverThreads()) +
                              "] (0: OpenMP default; at most 4 x the " + std::to_string(MaxSolverThreads() / 4) +
                              " processors)";
  ExpectRefusals({
      {{"run", "cantilever", "--steps", "0"}, 2, Invalid("--steps = 0 is invalid: must be an integer >= 1")},
      {{"run", "cantilever", "--steps", "-5"}, 2, Invalid("--steps = -5 is invalid: must be an integer >= 1")},
      {{"run", "cantilever", "--steps", "2.5"}, 2, Invalid("--steps = 2.5 is invalid: must be an integer >= 1")},
      {{"run", "cantilever", "--dt", "0"}, 2, Invalid("--dt = 0 is invalid: must be finite and > 0 (s)")},
      {{"run", "cantilever", "--dt", "-1"}, 2, Invalid("--dt = -1 is invalid: must be finite and > 0 (s)")},
      {{"run", "cantilever", "--dt", "nan"}, 2, Invalid("--dt = nan is invalid: must be finite and > 0 (s)")},
      {{"run", "cantilever", "--dt", "inf"}, 2, Invalid("--dt = inf is invalid: must be finite and > 0 (s)")},
      {{"run", "cantilever", "--rtol", "0"}, 2, Invalid("--rtol = 0 is invalid: must be in (0, 1)")},
      {{"run", "cantilever", "--rtol", "-1"}, 2, Invalid("--rtol = -1 is invalid: must be in (0, 1)")},
      {{"run", "cantilever", "--rtol", "nan"}, 2, Invalid("--rtol = nan is invalid: must be in (0, 1)")},
      {{"run", "cantilever", "--lbfgs-scale", "2"}, 2, Invalid("--lbfgs-scale = 2 is invalid: must be in (0, 1]")},
      {{"run", "cantilever", "--threads", "99999"}, 2, Invalid("--threads = 99999 is invalid: " + threads)},
      {{"run", "cantilever", "--threads", "-1"}, 2, Invalid("--threads = -1 is invalid: " + threads)},
      {{"run", "cantilever", "--verbosity", "3"},
       2,
       Invalid("--verbosity = 3 is invalid: must be an integer in [0, 2]")},
      {{"gradcheck", "cantilever", "--dt", "-1"}, 2, Invalid("--dt = -1 is invalid: must be finite and > 0 (s)")},
      {{"gradcheck", "cantilever", "--steps", "0"}, 2, Invalid("--steps = 0 is invalid: must be an integer >= 1")},
      {{"gradcheck", "cantilever", "--early-stop", "0.5"},
       2,
       Invalid("--early-stop = 0.5 is invalid: must be 0 or finite and >= 1")},
      {{"gradcheck", "cantilever", "--early-stop", "nan"},
       2,
       Invalid("--early-stop = nan is invalid: must be 0 or finite and >= 1")},
      {{"gradcheck", "cantilever", "--concurrent-rollouts", "0"},
       2,
       Invalid("--concurrent-rollouts = 0 is invalid: must be an integer in [1, " + std::to_string(MaxSolverThreads()) +
               "]")},
      {{"run", "calibrate-plant", "--max-iterations", "-5"},
       2,
       Invalid("--max-iterations = -5 is invalid: must be an integer >= 1")},
      {{"run", "starfish-control", "--evaluations", "0"},
       2,
       Invalid("--evaluations = 0 is invalid: must be an integer in [1, 100000]")},
      {{"run", "starfish-control", "--evaluations", "-3"},
       2,
       Invalid("--evaluations = -3 is invalid: must be an integer in [1, 100000]")},
      {{"run", "starfish-control", "--evaluations", "2.5"},
       2,
       Invalid("--evaluations = 2.5 is invalid: must be an integer in [1, 100000]")},
      {{"run", "shark-control", "--evaluations", "1e9"},
       2,
       Invalid("--evaluations = 1e9 is invalid: must be an integer in [1, 100000]")},
      {{"run", "starfish-control", "--seed", "-1"},
       2,
       Invalid("--seed = -1 is invalid: must be an integer in [0, 2147483647]")},
      {{"run", "starfish-control", "--seed", "99999999999999999999"},
       2,
       Invalid("--seed = 99999999999999999999 is invalid: must be an integer in [0, 2147483647]")},
      {{"run", "starfish-control", "--optimizer", "sgd"},
       2,
       Invalid("optimizer 'sgd' is unknown: valid optimizers are adam, lbfgs, ipopt")},
      {{"run", "calibrate-starfish", "--seconds", "-1"},
       2,
       Invalid("--seconds = -1 is invalid: must be finite and > 0 (s)")},
      {{"run", "calibrate-starfish", "--seconds", "0"},
       2,
       Invalid("--seconds = 0 is invalid: must be finite and > 0 (s)")},
      {{"run", "calibrate-starfish", "--starts", "0"},
       2,
       Invalid("--starts = 0 is invalid: must be an integer in [1, 4]")},
      {{"run", "calibrate-starfish", "--starts", "5"},
       2,
       Invalid("--starts = 5 is invalid: must be an integer in [1, 4]")},
      {{"run", "calibrate-starfish", "--density", "free"},
       2,
       Invalid("--density = 'free' is invalid: calibrate-starfish knows 'fitted' or 'fixed'")},
      {{"run", "calibrate-starfish", "--damping", "yes"},
       2,
       Invalid("--damping = 'yes' is invalid: calibrate-starfish knows 'fitted' or 'fixed'")},
  });
}

TEST(CommandLineTest, RefusesOptionsTheProblemWouldIgnore) {
  ExpectRefusals({
      {{"run", "cantilever", "--ipopt", "tol=1e-3"},
       2,
       Invalid("--ipopt is not used by the simulation problem 'cantilever' (only the optimisation problems read it)")},
      {{"run", "cantilever", "--data", "m.csv"},
       2,
       Invalid("--data is not used by the simulation problem 'cantilever' (only calibrate-plant and "
               "calibrate-bouncing-ball read it)")},
      {{"run", "falling-cube", "--small"},
       2,
       Invalid("--small is not used by the simulation problem 'falling-cube' (only the optimisation and control "
               "problems read it)")},
      {{"run", "rolling-sphere", "--max-iterations", "3"},
       2,
       Invalid("--max-iterations is not used by the simulation problem 'rolling-sphere' (only the calibration "
               "problems read it)")},
      {{"run", "bunny", "--data", "m.csv"},
       2,
       Invalid("--data is not used by the optimisation problem 'bunny' (only calibrate-plant and "
               "calibrate-bouncing-ball read it)")},
      {{"run", "calibrate-plant", "--ipopt", "tol=1e-3"},
       2,
       Invalid("--ipopt is not used by the calibration problem 'calibrate-plant' (only the optimisation problems read "
               "it)")},
      {{"run", "calibrate-plant", "--seconds", "3"},
       2,
       Invalid("--seconds is not used by the calibration problem 'calibrate-plant' (only calibrate-starfish read it)")},
      {{"run", "calibrate-plant", "--starts", "2"},
       2,
       Invalid("--starts is not used by the calibration problem 'calibrate-plant' (only calibrate-starfish read it)")},
      {{"run", "calibrate-plant", "--damping", "fitted"},
       2,
       Invalid("--damping is not used by the calibration problem 'calibrate-plant' (only calibrate-starfish read it)")},
      {{"run", "calibrate-starfish", "--small"},
       2,
       Invalid("--small is not used by the starfish calibration 'calibrate-starfish' (only the optimisation and "
               "control problems read it)")},
      {{"run", "cantilever", "--evaluations", "5"},
       2,
       Invalid("--evaluations is not used by the simulation problem 'cantilever' (only the control problems read it)")},
      {{"run", "cantilever", "--optimizer", "adam"},
       2,
       Invalid("--optimizer is not used by the simulation problem 'cantilever' (only the control problems read it)")},
      {{"run", "bunny", "--seed", "3"},
       2,
       Invalid("--seed is not used by the optimisation problem 'bunny' (only the control problems read it)")},
      {{"run", "starfish-control", "--ipopt", "tol=1e-3"},
       2,
       Invalid("--ipopt is not used by the control problem 'starfish-control' (only the optimisation problems read "
               "it)")},
      {{"run", "shark-control", "--steps", "5"},
       2,
       Invalid("--steps and --dt are fixed by the control problem 'shark-control'; use --small for the reduced "
               "instance")},
  });
}

TEST(CommandLineTest, RefusesUnreadableOrOutOfRangeCapturedMotion) {
  const std::string folder = TempPath("folder.csv");
  std::filesystem::create_directories(folder);
  const std::string markers = "marker,0,vertex,0\nmarker,1,vertex,230\ntime,marker,x,y,z\n0.01,0,0,0,0.1\n";
  const std::string far = WriteTemp("far.csv", markers + "0.02,1,1e300,0,0.1\n");
  const std::string late = WriteTemp("late.csv", markers + "1e300,1,0,0,0.1\n");
  const std::string weighty =
      WriteTemp("weighty.csv", "marker,0,vertex,0\ntime,marker,x,y,z,wx,wy,wz\n0.01,0,0,0,0.1,1,1e300,1\n");
  ExpectRefusals({
      {{"run", "calibrate-bouncing-ball", "--data", folder},
       2,
       Invalid("cannot open '" + folder + "': it is a directory, not a file")},
      {{"run", "calibrate-bouncing-ball", "--data", far},
       2,
       Invalid(far + ":5: x = 1e+300 is invalid: must be within +-1000000 (m)")},
      {{"run", "calibrate-bouncing-ball", "--data", weighty},
       2,
       Invalid(weighty + ":3: wy = 1e+300 is invalid: weights must be <= 1000000000000 (1/m)")},
      {{"run", "calibrate-bouncing-ball", "--data", late},
       2,
       Invalid("line 5: time 1e+300 s needs 5e+302 steps of 0.002 s, more than the limit of 100000 "
               "(MarkerObservations::kMaxSteps)")},
  });
}

TEST(CommandLineTest, RefusesBadMeshSizesThreadsAndProblemsOfTheTools) {
  std::string problems;
  for (const auto& p : AllProblems()) problems += (problems.empty() ? "" : ", ") + p->name();
  const std::string threads = "must be an integer in [0, " + std::to_string(MaxSolverThreads()) +
                              "] (0: OpenMP default; at most 4 x the " + std::to_string(MaxSolverThreads() / 4) +
                              " processors)";
  ExpectRefusals({
      {{"bench", "cantilever", "--refine", "100"},
       2,
       Invalid("--refine = 100 is invalid: must be an integer in [-9, 12]")},
      {{"stress", "--refine", "100"}, 2, Invalid("--refine = 100 is invalid: must be an integer in [-9, 12]")},
      {{"stress", "--refine", "-10"}, 2, Invalid("--refine = -10 is invalid: must be an integer in [-9, 12]")},
      {{"tradeoff", "cantilever", "--refine", "13"},
       2,
       Invalid("--refine = 13 is invalid: must be an integer in [-9, 12]")},
      {{"bench", "cantilever", "--threads", "99999"}, 2, Invalid("--threads = 99999 is invalid: " + threads)},
      {{"stress", "--threads", "99999"}, 2, Invalid("--threads = 99999 is invalid: " + threads)},
      {{"tradeoff", "cantilever", "--threads", "-1"}, 2, Invalid("--threads = -1 is invalid: " + threads)},
      {{"bench", "cantilever", "--repeat", "0"}, 2, Invalid("--repeat = 0 is invalid: must be an integer >= 1")},
      {{"bench", "cantilever", "--dt", "0"}, 2, Invalid("--dt = 0 is invalid: must be finite and > 0 (s)")},
      {{"stress", "--steps", "0"}, 2, Invalid("--steps = 0 is invalid: must be an integer >= 1")},
      {{"stress", "--energy-tol", "-1"}, 2, Invalid("--energy-tol = -1 is invalid: must be finite and >= 0")},
      {{"stress", "--E", "1e6,-1"}, 2, Invalid("--E = -1 is invalid: must be finite and > 0 (Pa)")},
      {{"stress", "--nu", "0.7"}, 2, Invalid("--nu = 0.7 is invalid: must be finite and in (-1, 0.5)")},
      {{"stress", "--dt", "0.01,0"}, 2, Invalid("--dt = 0 is invalid: must be finite and > 0 (s)")},
      {{"tradeoff", "cantilever", "--dt-levels", "0"},
       2,
       Invalid("--dt-levels = 0 is invalid: must be an integer >= 1")},
      {{"tradeoff"}, 2, Invalid("name one problem or give --all (diffpd tradeoff --help lists the problems)")},
      {{"tradeoff", "cantilever", "--all"},
       2,
       Invalid("name one problem or give --all (diffpd tradeoff --help lists the problems)")},
      {{"tradeoff", "cantilever", "--repeats", "0"}, 2, Invalid("--repeats = 0 is invalid: must be an integer >= 1")},
      {{"tradeoff", "cantilever", "--clock", "gpu"}, 2, Invalid("--clock gpu is invalid: valid clocks are wall, cpu")},
      {{"tradeoff", "cantilever", "--shard", "1/2"}, 2, Invalid("--shard needs --all")},
      {{"tradeoff", "--all", "--shard", "3/2"}, 2, Invalid("--shard 3/2 is invalid: must be K/N with 1 <= K <= N")},
      {{"tradeoff", "--all", "--shard", "1/0"}, 2, Invalid("--shard 1/0 is invalid: must be K/N with 1 <= K <= N")},
      {{"tradeoff", "--all", "--shard", "2"}, 2, Invalid("--shard 2 is invalid: must be K/N with 1 <= K <= N")},
      {{"tradeoff", "bunny-x"},
       2,
       Invalid("problem 'bunny-x' has no trade-off objective: valid problems are " + TradeoffProblems())},
      {{"tradeoff", "starfish-control", "--dt", "0.01"},
       2,
       Invalid("--dt is invalid for starfish-control: the problem fixes its time step")},
      {{"tradeoff", "cantilever", "--paper-size"},
       2,
       Invalid("the paper's size is invalid for cantilever: only the paper's rows (paper-<row>) have a paper-size "
               "instance")},
      {{"tradeoff", "--all", "--paper-size"},
       2,
       Invalid("--paper-size is invalid with --all: name one paper row (paper-<row>)")},
      {{"tradeoff", "cantilever", "--masses", "lumped"},
       2,
       Invalid("masses 'lumped' are invalid for cantilever: only the paper's rows (paper-<row>) choose their masses")},
      {{"tradeoff", "--all", "--masses", "lumped"},
       2,
       Invalid("--masses is invalid with --all: name one paper row (paper-<row>)")},
      {{"tradeoff", "paper-bunny", "--masses", "heavy"},
       2,
       Invalid("masses 'heavy' is unknown: use lumped or equal-nodes")},
      {{"stress", "--problems", "nosuch"}, 2, Invalid("unknown problem 'nosuch': valid problems are " + problems)},
      {{"stress", "--problems", "starfish-control"},
       2,
       Invalid("problem 'starfish-control' cannot be refined: refinement is available for cantilever, falling-cube, "
               "bouncing-ball and rolling-sphere")},
      {{"run", "nosuch"}, 2, Invalid("unknown problem 'nosuch': valid problems are " + problems)},
  });
}

}  // namespace
}  // namespace diffpd::problems
