// `diffpd tradeoff`: the command-line edge of tradeoff.h and tradeoff_front.h.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/option_checks.h"
#include "diffpd/error.h"
#include "tools/bench.h"
#include "tools/optimiser_tradeoff.h"
#include "tools/problem_objective.h"
#include "tools/tradeoff.h"
#include "tools/tradeoff_front.h"

namespace diffpd::problems {
namespace {

constexpr const char* kTradeoffFooter = R"(
Time (forward + backward seconds of one evaluation) against the error of the
problem's own loss and of its gradient with respect to the problem's own
optimisation variables, against newton-cholesky converged to rel_tolerance
1e-10 (adjoint 1e-12; no contact screening, the contact energy guard at
1e-2), cached in --cache (default <out>/reference_cache).
Every run starts from the problem's own settings ('default'); sweeps:
 tolerance  : each --methods at each --tolerances value
 options    : the other tolerance reference (start residual / inertia) per
              tolerance; pd and pd-lbfgs with each adjoint solver (auto,
              iterative, direct) and each backward tolerance factor; the
              contact screening tolerance where the scene has contact
 time_step  : forward scenes: h = dt / 2^k, k < --dt-levels, fixed duration
 resolution : cantilever, falling-cube: 3 fewer doublings per level
Problems: every registered problem (small instances of the optimisation and
control problems), the paper's rows as paper-<row> (small; --paper-size: at
the paper's size, the Table's mesh and steps; the Table's masses, the
original code's equal node masses, unless --masses lumped), the calibrations.
--all: every problem's small instance (but paper-starfish and paper-shark,
whose small instances are starfish-control's and shark-control's), checked
rather than measured: the tolerance sweep of pd-lbfgs at 1e-2, 1e-4, 1e-6 (unless --methods, --sweeps,
--tolerances say otherwise), forward scenes at 3 steps on coarse meshes;
with --check a few minutes on 2 cores in all (--shard K/N splits it).
--quick: four tolerances (1e-2 to 1e-8), every --methods, the solver-option
sweeps, two time-step and resolution levels, forward scenes at 10 steps
(with --all: every problem so).
--out DIR writes <problem>.json (the report below) and, with gnuplot,
<problem>.png (log-log, one curve per method, the default marked); --all
also writes summary.json. Report: default (method, tolerance, seconds,
gradient error, slowdown over the front), the front, for gradient-error
bounds 1e-3, 1e-2, 1e-1 the fastest setting and how far the default's
tolerance may be loosened, and the monotonicity violations (a tighter
tolerance with a larger error than --noise times a looser one's plus 1e-9).
Each setting runs once (--repeats N: N times, its fastest run kept: on a
shared machine the default, run first, is otherwise measured slower).
--clock wall (default): seconds are the wall time of the forward and
backward passes; --clock cpu: the process's CPU seconds of the whole
evaluation (with --threads 1 the measure to compare settings by on a machine
shared with other work; every row also reports cpu_s).
Exit code 6 with --check when a problem has a monotonicity violation.
--optimiser: instead, the problem's own optimiser (Ipopt, Ceres or Adam) from
its own start with every evaluation at each --tolerances value (default
method), its wall time and its final point's loss re-evaluated converged;
--budget N caps each run's iterations (Adam: evaluations; paper rows:
rollouts). --out DIR writes <problem>_optimiser.json and .png; --all runs
every problem that has an optimiser.)";

struct TradeoffArgs {
  std::string problem;
  bool all = false;
  bool quick = false;
  std::string shard;
  // Whether the user named these (--all then keeps them).
  bool methods_given = false, sweeps_given = false, tolerances_given = false;
  std::vector<std::string> methods = {"pd", "pd-lbfgs", "newton-pcg", "newton-cholesky", "newton-ldlt"};
  std::vector<std::string> sweeps = {"tolerance", "options", "time_step", "resolution"};
  TradeoffOptions options;
  bool json = false;
  bool check = false;
  double noise = 3;
  std::string out;
  std::string plot;
  std::string clock = "wall";
  std::string masses;  // "": a paper row's default (the Table's)
  bool optimiser = false;
  int budget = 0;
  std::string replot;
};

// The reduced settings of --quick (and --all --quick): four tolerances, two
// time-step and resolution levels, forward scenes at 10 steps on coarse
// meshes.
void Reduce(const std::string& problem, TradeoffOptions* o) {
  o->tolerances = {1e-2, 1e-4, 1e-6, 1e-8};
  o->backward_factors = {1, 0.01};
  o->screenings = {0, 1e-1};
  o->time_step_levels = 2;
  o->resolution_levels = 2;
  if (o->instance.steps <= 0) o->instance.steps = 10;
  if (o->instance.refine == 0) o->instance.refine = problem == "cantilever" ? -6 : problem == "falling-cube" ? -3 : 0;
}

// The check of --all: the tolerance sweep of pd-lbfgs (every problem's
// default method) at 1e-2, 1e-4 and 1e-6, forward scenes at 3 steps on
// coarse meshes; what the user names explicitly is kept.
void ReduceToCheck(const std::string& problem, const TradeoffArgs& args, TradeoffOptions* o) {
  if (!args.tolerances_given) o->tolerances = {1e-2, 1e-4, 1e-6};
  if (!args.methods_given) o->methods = {Method::kPdLbfgs};
  if (!args.sweeps_given) o->sweep_solver_options = o->sweep_time_step = o->sweep_resolution = false;
  o->time_step_levels = std::min(o->time_step_levels, 2);
  o->resolution_levels = std::min(o->resolution_levels, 2);
  if (o->instance.steps <= 0) o->instance.steps = 3;
  if (o->instance.refine == 0) o->instance.refine = problem == "cantilever" ? -6 : problem == "falling-cube" ? -3 : 0;
}

// A front plot's title: the problem and its instance's size.
std::string FrontTitle(const std::string& problem, int dofs, int steps) {
  return "diffpd tradeoff: " + problem + " (" + std::to_string(dofs) + " DoFs, " + std::to_string(steps) + " steps)";
}

// The problems of shard "K/N" of `names`: those at positions i with
// i mod N = K - 1. Throws InvalidInputError for anything but 1 <= K <= N.
std::vector<std::string> Shard(const std::vector<std::string>& names, const std::string& shard) {
  if (shard.empty()) return names;
  long k = 0, n = 0;
  char slash = 0, extra = 0;
  if (std::sscanf(shard.c_str(), "%ld%c%ld%c", &k, &slash, &n, &extra) != 3 || slash != '/' || k < 1 || k > n)
    throw InvalidInputError("--shard " + shard + " is invalid: must be K/N with 1 <= K <= N");
  std::vector<std::string> out;
  for (size_t i = 0; i < names.size(); ++i)
    if (static_cast<long>(i % n) == k - 1) out.push_back(names[i]);
  return out;
}

struct ProblemReport {
  TradeoffResult result;
  TradeoffFront front;
  std::vector<MonotonicityViolation> violations;
};

void PrintTable(const ProblemReport& p) {
  const TradeoffResult& r = p.result;
  const std::string masses = r.masses.empty() ? "" : ", " + r.masses + " masses";
  std::printf("== %s: %d DoFs, %d steps, h = %g s%s; gradient w.r.t. %s; loss %s\n", r.problem.c_str(), r.dofs, r.steps,
              r.time_step, masses.c_str(), r.variables.c_str(), r.loss.c_str());
  std::printf("%-19s %-16s %-25s %10s %-14s %10s %11s %11s %11s %8s\n", "sweep", "method", "parameter", "value",
              "setting", "seconds", "state_err", "loss_err", "grad_err", "it/step");
  for (const auto& row : r.rows) {
    std::printf("%-19s %-16s %-25s %10.3g %-14s ", row.sweep.c_str(), row.method.c_str(), row.parameter.c_str(),
                row.value, row.setting.c_str());
    if (!row.ok())
      std::printf("failed: %s\n", row.failure.c_str());
    else
      std::printf("%10.4f %11.3e %11.3e %11.3e %8.2f\n", row.seconds, row.state_rel_error, row.loss_rel_error,
                  row.grad_rel_error, row.iters_per_step);
  }
  if (!r.rows[0].ok())
    std::printf("default %s at rel_tolerance %g failed: %s\n", r.default_method.c_str(), r.default_rel_tolerance,
                r.rows[0].failure.c_str());
  else
    std::printf("default %s at rel_tolerance %g: %.4f s, gradient error %.3e, %.2fx the front's time at that error%s\n",
                r.default_method.c_str(), r.default_rel_tolerance, p.front.default_seconds, r.rows[0].grad_rel_error,
                p.front.default_slowdown, p.front.default_on_front ? " (on the front)" : "");
  for (const auto& b : p.front.bounds) {
    if (!b.met) {
      std::printf("gradient error <= %g: no run reaches it\n", b.bound);
      continue;
    }
    std::printf("gradient error <= %g: fastest %s (%s, rel_tolerance %g) %.4f s; ", b.bound, b.method.c_str(),
                b.setting.c_str(), b.rel_tolerance, b.seconds);
    if (b.default_method_tolerance > 0)
      std::printf("%s meets it from rel_tolerance %g down (%gx the default)\n", r.default_method.c_str(),
                  b.default_method_tolerance, b.loosening);
    else
      std::printf("%s meets it at no swept tolerance\n", r.default_method.c_str());
  }
  for (const auto& v : p.violations)
    std::printf("NOT MONOTONE: %s %s error %.3e at rel_tolerance %g > %.3e at %g\n", v.method.c_str(), v.error.c_str(),
                v.tighter_error, v.tighter_tolerance, v.looser_error, v.looser_tolerance);
}

void PrintOptimiserTable(const OptimiserTradeoff& t) {
  std::printf("== %s: %d DoFs, %d steps; %s, every evaluation %s at the tolerance below (default %g)\n",
              t.problem.c_str(), t.dofs, t.steps, t.optimiser.c_str(), t.method.c_str(), t.default_rel_tolerance);
  std::printf("%10s %10s %6s %6s %14s %14s %14s %10s %10s  %s\n", "rel_tol", "wall_s", "evals", "iters", "initial_loss",
              "final_loss", "reported_loss", "shortfall", "violation", "status");
  for (const auto& r : t.rows) {
    const OptimiserOutcome& o = r.outcome;
    if (!o.ok()) {
      std::printf("%10.3g failed: %s\n", r.rel_tolerance, o.failure.c_str());
      continue;
    }
    std::printf("%10.3g %10.3f %6ld %6d %14.7e %14.7e %14.7e %10.3g %10.3g  %s\n", r.rel_tolerance, o.wall_s,
                o.evaluations, o.iterations, o.initial_loss, o.final_loss, o.reported_loss, r.shortfall,
                o.constraint_violation, o.status.c_str());
  }
}

int RunOptimiserTradeoffArgs(const TradeoffArgs& args, const std::vector<std::string>& problems) {
  nlohmann::json summary = nlohmann::json::array();
  OptimiserTradeoffOptions options;
  options.max_iterations = args.budget;
  for (const auto& name : problems) {
    const ProblemObjective objective = MakeProblemObjective(name, args.options.threads, args.options.instance);
    if (!objective.optimise) {
      if (args.all) continue;
      throw InvalidInputError("problem '" + name +
                              "' has no optimiser of its own (a forward scene): --optimiser needs an optimisation, "
                              "calibration or control problem");
    }
    std::vector<double> tolerances = args.options.tolerances;
    if (args.all || args.quick) tolerances = {1e-2, 1e-4, 1e-6, 1e-8};
    const OptimiserTradeoff t = RunOptimiserTradeoff(objective, tolerances, options, &std::cerr);
    const nlohmann::json report = OptimiserTradeoffJson(t);
    summary.push_back(report);
    if (!args.out.empty()) {
      const auto base = std::filesystem::path(args.out) / (name + "_optimiser");
      std::ofstream(base.string() + ".json") << report.dump(1) << "\n";
      if (GnuplotAvailable()) {
        WriteOptimiserTradeoffPlot(t, base.string() + ".png");
        std::cerr << "[tradeoff] wrote " << base.string() << ".png" << std::endl;
      }
    }
    if (!args.plot.empty()) WriteOptimiserTradeoffPlot(t, args.plot);
    if (!args.json) PrintOptimiserTable(t);
    std::fflush(stdout);
  }
  if (!args.out.empty() && args.all)
    std::ofstream((std::filesystem::path(args.out) / "optimiser_summary.json").string()) << summary.dump(1) << "\n";
  if (args.json) std::printf("%s\n", (args.all ? summary : summary[0]).dump(2).c_str());
  return 0;
}

int RunTradeoffArgs(const TradeoffArgs& args) {
  if (!args.replot.empty()) {
    if (args.plot.empty()) throw InvalidInputError("--replot needs --plot FILE.png (where to draw the report)");
    std::ifstream in(args.replot);
    if (!in) throw InvalidInputError("--replot " + args.replot + " is invalid: the file cannot be read");
    nlohmann::json report;
    try {
      in >> report;
    } catch (const nlohmann::json::exception& e) {
      throw InvalidInputError("--replot " + args.replot + " is invalid: not JSON (" + e.what() + ")");
    }
    if (report.is_object() && report.contains("front")) {
      // A front's report (<problem>.json).
      try {
        const std::string title = FrontTitle(report.at("problem").get<std::string>(), report.at("dofs").get<int>(),
                                             report.at("steps").get<int>());
        const TradeoffClock clock =
            report.value("clock", std::string("wall")) == "cpu" ? TradeoffClock::kCpu : TradeoffClock::kWall;
        WriteTradeoffPlot(TradeoffRowsFromJson(report.at("rows")), args.plot, title, clock);
      } catch (const nlohmann::json::exception& e) {
        throw InvalidInputError("--replot " + args.replot + " is invalid: not a report of diffpd tradeoff (" +
                                e.what() + ")");
      }
    } else {
      WriteOptimiserTradeoffPlot(OptimiserTradeoffFromJson(report), args.plot);
    }
    std::cerr << "[tradeoff] wrote " << args.plot << std::endl;
    return 0;
  }
  if (args.all == !args.problem.empty())
    throw InvalidInputError("name one problem or give --all (diffpd tradeoff --help lists the problems)");
  TradeoffOptions options = args.options;
  if (args.clock != "wall" && args.clock != "cpu")
    throw InvalidInputError("--clock " + args.clock + " is invalid: valid clocks are wall, cpu");
  options.clock = args.clock == "cpu" ? TradeoffClock::kCpu : TradeoffClock::kWall;
  options.methods = ParseMethods(args.methods);
  if (!args.masses.empty()) options.instance.paper_masses = ParseMassLumping(args.masses);
  options.sweep_tolerance = options.sweep_solver_options = options.sweep_time_step = options.sweep_resolution = false;
  for (const auto& s : args.sweeps) {
    if (s == "tolerance")
      options.sweep_tolerance = true;
    else if (s == "options")
      options.sweep_solver_options = true;
    else if (s == "time_step")
      options.sweep_time_step = true;
    else if (s == "resolution")
      options.sweep_resolution = true;
    else
      throw InvalidInputError("sweep '" + s +
                              "' is invalid: valid sweeps are tolerance, options, time_step, resolution");
  }
  if (!(args.noise >= 1))
    throw InvalidInputError("--noise = " + std::to_string(args.noise) + " is invalid: must be >= 1");
  if (options.cache_dir.empty() && !args.out.empty())
    options.cache_dir = (std::filesystem::path(args.out) / "reference_cache").string();
  if (!args.out.empty()) std::filesystem::create_directories(args.out);
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
  if (!args.shard.empty() && !args.all) throw InvalidInputError("--shard needs --all");
  if (options.instance.paper_size && args.all)
    throw InvalidInputError("--paper-size is invalid with --all: name one paper row (paper-<row>)");
  if (options.instance.paper_masses && args.all)
    throw InvalidInputError("--masses is invalid with --all: name one paper row (paper-<row>)");
  const std::vector<std::string> problems =
      args.all ? Shard(AllSweepProblemNames(), args.shard) : std::vector<std::string>{args.problem};
  if (args.optimiser) return RunOptimiserTradeoffArgs(args, problems);
  std::vector<ProblemReport> reports;
  nlohmann::json summary = nlohmann::json::array();
  bool monotone = true;
  for (const auto& name : problems) {
    TradeoffOptions o = options;
    if (args.quick)
      Reduce(name, &o);
    else if (args.all)
      ReduceToCheck(name, args, &o);
    ProblemReport p;
    p.result = RunTradeoff(name, o, &std::cerr);
    p.front = AnalyseFront(p.result);
    p.violations = CheckMonotone(p.result.rows, args.noise, 1e-9);
    monotone = monotone && p.violations.empty();
    const nlohmann::json report = TradeoffReportJson(p.result, p.front, p.violations);
    summary.push_back(report);
    const std::string title = FrontTitle(name, p.result.dofs, p.result.steps);
    if (!args.out.empty()) {
      const auto base = std::filesystem::path(args.out) / name;
      std::ofstream(base.string() + ".json") << report.dump(1) << "\n";
      if (GnuplotAvailable()) {
        WriteTradeoffPlot(p.result.rows, base.string() + ".png", title, p.result.clock);
        std::cerr << "[tradeoff] wrote " << base.string() << ".png" << std::endl;
      }
    }
    if (!args.plot.empty()) {
      WriteTradeoffPlot(p.result.rows, args.plot, title, p.result.clock);
      std::cerr << "[tradeoff] wrote " << args.plot << std::endl;
    }
    if (!args.json) PrintTable(p);
    std::fflush(stdout);
  }
  if (!args.out.empty() && args.all)
    std::ofstream((std::filesystem::path(args.out) / "summary.json").string()) << summary.dump(1) << "\n";
  if (args.json) std::printf("%s\n", (args.all ? summary : summary[0]).dump(2).c_str());
  return args.check && !monotone ? 6 : 0;
}

}  // namespace

Subcommand AddTradeoffCommand(CLI::App* parent) {
  auto args = std::make_shared<TradeoffArgs>();
  CLI::App* cmd = parent->add_subcommand(
      "tradeoff", "time vs. error of a problem's loss and gradient per method, tolerance and solver option");
  cmd->footer(kTradeoffFooter);
  TradeoffOptions& o = args->options;
  cmd->add_option("problem", args->problem, "problem name (diffpd list; paper rows as paper-<row>)");
  cmd->add_flag("--all", args->all, "every problem's small instance, pd-lbfgs's tolerance sweep (see below)");
  cmd->add_option("--shard", args->shard, "--all: only the problems at positions i with i mod N = K - 1 (K/N)");
  cmd->add_flag("--quick", args->quick, "reduced sweeps of every method (the fronts of docs/results/tradeoff)");
  cmd->add_option("--methods", args->methods,
                  "comma-separated methods: newton-cholesky, newton-pcg, newton-ldlt, pd, pd-lbfgs")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--sweeps", args->sweeps, "comma-separated sweeps: tolerance, options, time_step, resolution")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--tolerances", o.tolerances, "comma-separated tolerances of the tolerance sweep")
      ->delimiter(',')
      ->capture_default_str();
  cmd->add_option("--rtol", o.rel_tolerance,
                  "tolerance of the time-step and resolution sweeps (default: the problem's)")
      ->check(Fraction("--rtol"));
  cmd->add_option("--max-iterations", o.max_iterations, "iteration limit of each step's solve (default: the problem's)")
      ->check(IntegerAtLeast("--max-iterations", 1));
  cmd->add_option("--steps", o.instance.steps, "forward scenes: number of time steps at --dt (default: the problem's)")
      ->check(IntegerAtLeast("--steps", 1));
  cmd->add_option("--dt", o.time_step, "forward scenes: coarsest time step in seconds (default: the problem's)")
      ->check(Positive("--dt", "s"));
  cmd->add_option("--dt-levels", o.time_step_levels, "time steps dt / 2^k, k < dt-levels")
      ->check(IntegerAtLeast("--dt-levels", 1))
      ->capture_default_str();
  cmd->add_option("--resolution-levels", o.resolution_levels, "meshes, each halving the cells per axis")
      ->check(IntegerAtLeast("--resolution-levels", 1))
      ->capture_default_str();
  cmd->add_option("--refine", o.instance.refine, "cell doublings of the (finest) mesh; cantilever -9 = 4x1x1")
      ->check(IntegerIn("--refine", kMinRefinement, kMaxRefinement))
      ->capture_default_str();
  cmd->add_flag("--paper-size", o.instance.paper_size,
                "paper-<row>: the row at the paper's size (the Table's mesh and steps), not reduced");
  cmd->add_option("--masses", args->masses,
                  "paper-<row>: equal-nodes (the original code's, as `diffpd table`: the default) or lumped (this "
                  "library's)");
  cmd->add_option("--threads", o.threads, "threads for element loops (0: OpenMP default)")
      ->check(ThreadCount("--threads"));
  cmd->add_option("--repeats", o.repeats, "timed runs of each setting; each row keeps its fastest")
      ->check(IntegerAtLeast("--repeats", 1))
      ->capture_default_str();
  cmd->add_option("--clock", args->clock, "what a row's seconds count: wall or cpu (see below)")->capture_default_str();
  cmd->add_option("--seed", o.seed, "seed of the forward scenes' loss vectors")->capture_default_str();
  cmd->add_option("--cache", o.cache_dir, "directory of cached references (default: <out>/reference_cache)");
  cmd->add_option("--out", args->out, "directory for <problem>.json, <problem>.png (and summary.json with --all)");
  cmd->add_option("--noise", args->noise, "noise factor of the monotonicity check")->capture_default_str();
  cmd->add_flag("--check", args->check, "exit code 6 when a tolerance sweep is not monotone");
  cmd->add_flag("--json", args->json, "print the report as JSON on stdout");
  cmd->add_option("--plot", args->plot, "write a log-log PNG of time vs. error (needs gnuplot)");
  cmd->add_flag("--optimiser", args->optimiser,
                "the problem's own optimiser at each tolerance: wall time and final loss (see below)");
  cmd->add_option("--replot", args->replot,
                  "draw a saved report again (with --plot): <problem>.json or <problem>_optimiser.json");
  cmd->add_option("--budget", args->budget, "--optimiser: iterations of each run (0: the problem's own budget)")
      ->check(IntegerAtLeast("--budget", 0))
      ->capture_default_str();
  return {cmd, [args, cmd] {
            args->methods_given = cmd->count("--methods") > 0;
            args->sweeps_given = cmd->count("--sweeps") > 0;
            args->tolerances_given = cmd->count("--tolerances") > 0;
            return RunTradeoffArgs(*args);
          }};
}

}  // namespace diffpd::problems
