#include "control/trajectory_optimization.h"

#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/commands.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/vtk_writer.h"

namespace diffpd::problems {
namespace {

using solvers::IpoptOptions;
using solvers::IpoptSummary;

const char* SizeName(InstanceSize size) { return size == InstanceSize::kSmall ? "small" : "full"; }

// Writes the history as "iteration objective" lines.
std::string WriteHistory(const std::string& dir, const std::string& stem, const std::vector<double>& history) {
  const std::string path = (std::filesystem::path(dir) / (stem + ".dat")).string();
  std::ofstream out(path);
  if (!out) throw InvalidInputError("cannot write '" + path + "'");
  out << "# iteration objective\n";
  out.precision(17);
  for (size_t i = 0; i < history.size(); ++i) out << i << " " << history[i] << "\n";
  return path;
}

// Plots the histories with gnuplot into <dir>/objective_history.png (log
// scale if every objective is positive); returns the path, or "" (with a
// message on stderr) if gnuplot failed.
std::string PlotHistories(const std::string& dir, const std::string& title,
                          const std::vector<std::pair<std::string, std::string>>& series, bool positive) {
  const std::string png = (std::filesystem::path(dir) / "objective_history.png").string();
  FILE* gp = popen("gnuplot 2>/dev/null", "w");
  if (!gp) {
    std::fprintf(stderr, "diffpd: gnuplot could not be started; no plot written\n");
    return "";
  }
  std::fprintf(gp, "set terminal pngcairo size 900,540\nset output '%s'\n", png.c_str());
  std::fprintf(gp, "set title '%s'\nset xlabel 'Ipopt iteration'\nset ylabel 'objective'\nset grid\n", title.c_str());
  if (positive) std::fprintf(gp, "set logscale y\nset format y '%%.0e'\n");
  std::fprintf(gp, "plot ");
  for (size_t i = 0; i < series.size(); ++i)
    std::fprintf(gp, "%s'%s' using 1:2 with linespoints title '%s'", i ? ", " : "", series[i].second.c_str(),
                 series[i].first.c_str());
  std::fprintf(gp, "\n");
  const int status = pclose(gp);
  if (status != 0 || !std::filesystem::exists(png)) {
    std::fprintf(stderr, "diffpd: gnuplot failed (status %d); no plot written\n", status);
    return "";
  }
  return png;
}

nlohmann::json RunJson(const OptimizationRun& run) {
  const IpoptSummary& s = run.summary;
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  return {{"status", s.status_name},
          {"objective", number(s.objective)},
          {"initial_objective", number(s.initial_objective)},
          {"constraint_violation", number(s.constraint_violation)},
          {"evaluations", s.evaluations},
          {"forward_s", s.forward_seconds},
          {"backward_s", s.backward_seconds},
          {"method", ToString(run.method)},
          {"iterations", s.iterations},
          {"adjoint_passes", s.backward_passes},
          {"total_s", s.total_seconds},
          {"improved", run.improved},
          {"returned_best_feasible", s.returned_best_feasible},
          {"required_objective", run.required_objective},
          {"jacobian_mode", solvers::ToString(run.jacobian_mode)},
          {"variables", run.num_variables},
          {"constraints", run.num_constraints},
          {"dofs", run.num_dofs},
          {"steps", run.num_steps}};
}

}  // namespace

std::string TrajectoryOptimizationProblem::improvement_rule() const {
  std::ostringstream s;
  s << "objective lowered by at least " << 100 * improvement_margin() << " % of |initial objective|";
  return s.str();
}

SolverOptions TrajectoryOptimizationProblem::BaseOptions(InstanceSize size) const {
  SolverOptions o;
  o.rel_tolerance = 1e-6;
  o.abs_tolerance = 1e-9;
  o.max_iterations = 20000;
  return o;
}

IpoptOptions TrajectoryOptimizationProblem::DefaultIpoptOptions(InstanceSize size) const {
  IpoptOptions o;
  o.int_options = {{"max_iter", size == InstanceSize::kSmall ? 30 : 100}};
  o.num_options = {{"tol", 1e-6}, {"acceptable_tol", 1e-4}};
  return o;
}

OptimizationReport RunOptimization(const TrajectoryOptimizationProblem& problem, const OptimizationSettings& settings) {
  if (settings.threads < 0) {
    std::ostringstream msg;
    msg << "threads = " << settings.threads << " is invalid: must be >= 0";
    throw InvalidInputError(msg.str());
  }
  OptimizationReport report;
  report.problem = problem.name();
  report.improvement_rule = problem.improvement_rule();
  std::vector<Method> methods = {settings.method};
  if (settings.compare_newton && settings.method != Method::kNewtonCholesky) methods.push_back(Method::kNewtonCholesky);
  if (!settings.out_dir.empty()) std::filesystem::create_directories(settings.out_dir);
  std::vector<std::pair<std::string, std::string>> histories;
  bool all_positive = true;

  for (size_t r = 0; r < methods.size(); ++r) {
    SolverOptions options = problem.BaseOptions(settings.size);
    options.method = methods[r];
    options.time_step = problem.time_step(settings.size);
    options.num_threads = settings.threads;
    if (settings.rel_tolerance > 0) options.rel_tolerance = settings.rel_tolerance;
    options.lbfgs_weight_scale = settings.lbfgs_weight_scale;
    options.rigid_mode_correction = settings.rigid_mode_correction;
    options.verbosity = settings.verbosity;
    Ipopt::SmartPtr<solvers::RolloutNlp> nlp = problem.MakeNlp(options, settings.size);
    IpoptOptions ipopt = problem.DefaultIpoptOptions(settings.size);
    ipopt.string_options.insert(ipopt.string_options.end(), settings.ipopt.string_options.begin(),
                                settings.ipopt.string_options.end());
    ipopt.int_options.insert(ipopt.int_options.end(), settings.ipopt.int_options.begin(),
                             settings.ipopt.int_options.end());
    ipopt.num_options.insert(ipopt.num_options.end(), settings.ipopt.num_options.begin(),
                             settings.ipopt.num_options.end());
    ipopt.echo = settings.log;

    OptimizationRun run;
    run.method = methods[r];
    run.jacobian_mode = nlp->ResolvedJacobianMode();
    run.num_variables = nlp->num_variables();
    run.num_constraints = nlp->num_constraints();
    run.num_dofs = nlp->function().simulator().num_dofs();
    run.num_steps = problem.steps(settings.size);
    if (settings.log)
      std::fprintf(settings.log,
                   "# %s (%s instance): %d DoFs, %d steps of %g s, method %s; %d variables, %d constraints, "
                   "constraint Jacobian by %s mode\n",
                   problem.name().c_str(), SizeName(settings.size), run.num_dofs, run.num_steps, options.time_step,
                   ToString(run.method), run.num_variables, run.num_constraints, solvers::ToString(run.jacobian_mode));
    run.summary = SolveWithIpopt(nlp, ipopt);
    const IpoptSummary& s = run.summary;
    run.required_objective = problem.RequiredObjective(s.initial_objective);
    run.improved =
        s.constraint_violation <= 1e-6 && std::isfinite(s.objective) && s.objective <= run.required_objective;
    if (settings.log) std::fprintf(settings.log, "# %s: %s\n", ToString(run.method), s.BriefReport().c_str());

    if (!settings.out_dir.empty()) {
      const std::string stem = std::string("objective_history_") + ToString(run.method);
      const std::string dat = WriteHistory(settings.out_dir, stem, s.objective_history);
      report.files.push_back(dat);
      histories.emplace_back(ToString(run.method), dat);
      for (double f : s.objective_history) all_positive = all_positive && f > 0;
      if (r == 0) {  // frames of the optimised motion of the main run
        const Rollout* rollout = nlp->RolloutAt(s.x);
        if (rollout) {
          const Mesh& mesh = nlp->function().scene().mesh;
          PvdWriter pvd((std::filesystem::path(settings.out_dir) / "frames").string(), problem.name());
          for (size_t k = 0; k < rollout->states.size(); ++k)
            pvd.AddFrame(k * options.time_step, mesh,
                         Eigen::Map<const Eigen::Matrix3Xd>(rollout->states[k].x.data(), 3, mesh.num_vertices()));
          pvd.Write();
          report.files.push_back(
              (std::filesystem::path(settings.out_dir) / "frames" / (problem.name() + ".pvd")).string());
        }
      }
    }
    report.runs.push_back(std::move(run));
  }
  if (report.runs.size() == 2) {
    auto sim_seconds = [](const OptimizationRun& run) {
      return run.summary.forward_seconds + run.summary.backward_seconds;
    };
    report.newton_time_ratio = sim_seconds(report.runs[1]) / std::max(sim_seconds(report.runs[0]), 1e-300);
  }
  if (!settings.out_dir.empty()) {
    const std::string png =
        PlotHistories(settings.out_dir, problem.name() + ": objective per Ipopt iteration", histories, all_positive);
    if (!png.empty()) report.files.push_back(png);
    const std::string json_path = (std::filesystem::path(settings.out_dir) / "summary.json").string();
    std::ofstream(json_path) << ReportJson(report).dump(2) << "\n";
    report.files.push_back(json_path);
  }
  return report;
}

std::string DescribeOutcome(const IpoptSummary& s) {
  std::string what;
  if (s.succeeded())
    what = "Ipopt found a locally optimal point";
  else if (s.infeasible())
    what = "Ipopt reports the problem infeasible: the constraints cannot be met";
  else if (s.status == Ipopt::Maximum_Iterations_Exceeded)
    what = "Ipopt stopped at its iteration limit before converging";
  else if (s.status == Ipopt::Restoration_Failed)
    what = "Ipopt could not find a feasible point (restoration failed)";
  else
    what = "Ipopt did not converge";
  what += " (" + s.status_name + ")";
  if (!s.last_error.empty() && !s.succeeded()) what += "; last evaluation failure: " + s.last_error;
  return what;
}

void PrintReport(const OptimizationReport& report, FILE* out) {
  std::fprintf(out, "\n%-16s %-30s %13s %13s %11s %6s %6s %9s %10s %10s\n", "method", "status", "objective",
               "initial_obj", "violation", "iters", "evals", "adjoints", "forward_s", "backward_s");
  for (const OptimizationRun& run : report.runs) {
    const IpoptSummary& s = run.summary;
    std::fprintf(out, "%-16s %-30s %13.6e %13.6e %11.3e %6d %6ld %9ld %10.3f %10.3f\n", ToString(run.method),
                 s.status_name.c_str(), s.objective, s.initial_objective, s.constraint_violation, s.iterations,
                 s.evaluations, s.backward_passes, s.forward_seconds, s.backward_seconds);
  }
  if (report.runs.size() == 2)
    std::fprintf(out, "newton-cholesky / %s simulation time (forward + backward): %.3f\n",
                 ToString(report.runs[0].method), report.newton_time_ratio);
  for (const OptimizationRun& run : report.runs)
    std::fprintf(out, "%s: %s; objective %s (%s: <= %.6e), constraints %s\n", ToString(run.method),
                 DescribeOutcome(run.summary).c_str(), run.improved ? "improved" : "NOT improved",
                 report.improvement_rule.c_str(), run.required_objective,
                 run.summary.constraint_violation <= 1e-6 ? "satisfied" : "VIOLATED");
  for (const std::string& f : report.files) std::fprintf(out, "wrote %s\n", f.c_str());
}

nlohmann::json ReportJson(const OptimizationReport& report) {
  nlohmann::json out = RunJson(report.runs.at(0));
  out["problem"] = report.problem;
  out["improvement_rule"] = report.improvement_rule;
  out["outcome"] = DescribeOutcome(report.runs[0].summary);
  if (report.runs.size() == 2) {
    out["newton_cholesky"] = RunJson(report.runs[1]);
    out["newton_time_ratio"] = report.newton_time_ratio;
  }
  return out;
}

std::string DefaultOutputDirectory(const std::string& problem) {
  return (std::filesystem::path("out") / problem).string();
}

int ExitCode(const OptimizationReport& report) {
  const OptimizationRun& run = report.runs.at(0);
  const IpoptSummary& s = run.summary;
  if (s.succeeded()) return 0;
  if (s.status == Ipopt::Maximum_Iterations_Exceeded && run.improved) return 0;
  return s.infeasible() ? 4 : 5;
}

void AddIpoptOption(const std::string& name_value, solvers::IpoptOptions* options) {
  const size_t eq = name_value.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == name_value.size())
    throw InvalidInputError("Ipopt option '" + name_value + "' is invalid: expected name=value");
  const std::string name = name_value.substr(0, eq), value = name_value.substr(eq + 1);
  size_t used = 0;
  try {
    const long i = std::stol(value, &used);
    if (used == value.size() && i >= INT32_MIN && i <= INT32_MAX) {
      options->int_options.emplace_back(name, static_cast<int>(i));
      return;
    }
  } catch (const std::exception&) {
  }
  try {
    const double d = std::stod(value, &used);
    if (used == value.size()) {
      options->num_options.emplace_back(name, d);
      return;
    }
  } catch (const std::exception&) {
  }
  options->string_options.emplace_back(name, value);
}

int TrajectoryOptimizationProblem::Run(const CommandArgs& args) const {
  if (args.steps > 0 || args.dt > 0)
    throw InvalidInputError("--steps and --dt are fixed by the optimisation problem '" + name() +
                            "'; use --small for the reduced instance");
  OptimizationSettings settings;
  settings.size = args.small ? InstanceSize::kSmall : InstanceSize::kFull;
  settings.method = args.method;
  settings.compare_newton = args.compare_newton;
  settings.threads = args.threads;
  settings.rel_tolerance = args.rel_tolerance;
  settings.lbfgs_weight_scale = args.lbfgs_weight_scale;
  settings.rigid_mode_correction = args.rigid_mode_correction;
  settings.verbosity = args.verbosity;
  settings.out_dir = args.out_dir.empty() ? DefaultOutputDirectory(name()) : args.out_dir;
  FILE* text = args.json ? stderr : stdout;
  settings.log = text;
  for (const std::string& o : args.ipopt_options) AddIpoptOption(o, &settings.ipopt);
  const OptimizationReport report = RunOptimization(*this, settings);
  PrintReport(report, text);
  if (!report.runs[0].summary.succeeded())
    std::fprintf(stderr, "diffpd: %s: %s%s\n", name().c_str(), DescribeOutcome(report.runs[0].summary).c_str(),
                 report.runs[0].improved ? "; the point reached is feasible and meets the improvement rule" : "");
  if (args.json) std::printf("%s\n", ReportJson(report).dump(2).c_str());
  return ExitCode(report);
}

}  // namespace diffpd::problems
