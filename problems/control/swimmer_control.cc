#include "control/swimmer_control.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/commands.h"
#include "control/swimmer_optimizers.h"
#include "diffpd/error.h"
#include "diffpd/solvers/core/controller_block.h"
#include "diffpd/vtk_writer.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Quotes a string for gnuplot's single-quoted strings ('' is a quote).
std::string GnuplotQuoted(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

}  // namespace

StripNetworkController MakeSwimmerController(const Swimmer& swimmer, std::uint64_t seed) {
  std::vector<int> widths = {swimmer.observation.size()};
  widths.insert(widths.end(), swimmer.hidden_widths.begin(), swimmer.hidden_widths.end());
  widths.push_back(swimmer.channels);
  Mlp network(widths, MlpNonlinearity::kTanh, MlpNonlinearity::kTanh);
  network.InitializeOrthogonal(seed, 5.0 / 3.0);
  return StripNetworkController(network, swimmer.observation,
                                MuscleDelayLine(swimmer.strips, static_cast<int>(swimmer.scene.muscles.size())),
                                swimmer.drives, swimmer.scene.mesh.num_vertices());
}

const char* ToString(ControlOptimizer optimizer) {
  switch (optimizer) {
    case ControlOptimizer::kAdam:
      return "adam";
    case ControlOptimizer::kLbfgs:
      return "lbfgs";
    case ControlOptimizer::kIpopt:
      return "ipopt";
  }
  return "";
}

ControlOptimizer ParseControlOptimizer(const std::string& name) {
  for (const ControlOptimizer o : {ControlOptimizer::kAdam, ControlOptimizer::kLbfgs, ControlOptimizer::kIpopt})
    if (name == ToString(o)) return o;
  throw InvalidInputError("optimizer '" + name + "' is unknown: valid optimizers are adam, lbfgs, ipopt");
}

bool ControlOptimizerAvailable(ControlOptimizer optimizer) {
  switch (optimizer) {
    case ControlOptimizer::kAdam:
      return true;
    case ControlOptimizer::kLbfgs:
      return DIFFPD_WITH_CERES;
    case ControlOptimizer::kIpopt:
      return DIFFPD_WITH_IPOPT;
  }
  return false;
}

double TrainingResult::best_reward() const {
  double best = -INFINITY;
  for (const TrainingEvaluation& e : history) best = std::max(best, e.reward);
  return best;
}

double TrainingResult::mean_forward_seconds() const {
  double sum = 0;
  int count = 0;
  for (const TrainingEvaluation& e : history)
    if (e.backward_seconds > 0) {
      sum += e.forward_seconds;
      ++count;
    }
  return count ? sum / count : 0.0;
}

double TrainingResult::mean_backward_seconds() const {
  double sum = 0;
  int count = 0;
  for (const TrainingEvaluation& e : history)
    if (e.backward_seconds > 0) {
      sum += e.backward_seconds;
      ++count;
    }
  return count ? sum / count : 0.0;
}

std::unique_ptr<solvers::RolloutFunction> MakeSwimmerFunction(const Swimmer& swimmer, const SolverOptions& options_in,
                                                              std::uint64_t seed) {
  SolverOptions options = options_in;
  options.time_step = swimmer.time_step;
  auto function = std::make_unique<solvers::RolloutFunction>(swimmer.scene, options, swimmer.steps);
  function->AddBlock(std::make_unique<solvers::ControllerBlock>(MakeSwimmerController(swimmer, seed)));
  function->AddFunctional(std::make_unique<SwimLossFunction>(swimmer.loss));
  return function;
}

TrainingResult TrainSwimmer(const Swimmer& swimmer, const SolverOptions& options, const TrainingSettings& settings) {
  if (!ControlOptimizerAvailable(settings.optimizer))
    throw InvalidInputError(std::string("optimizer '") + ToString(settings.optimizer) + "' needs the " +
                            (settings.optimizer == ControlOptimizer::kLbfgs ? "Ceres" : "Ipopt") +
                            " adapter, which this build lacks");
  std::unique_ptr<solvers::RolloutFunction> function = MakeSwimmerFunction(swimmer, options, settings.seed);
  EvaluationBudget budget(function.get(), settings.evaluations, swimmer.steps, settings.log);
  constexpr int kLoss = 0;

  TrainingResult result;
  result.optimizer = ToString(settings.optimizer);
  result.method = options.method;
  result.dofs = swimmer.scene.mesh.num_dofs();
  result.steps = swimmer.steps;
  result.parameters = function->num_parameters();
  result.time_step = swimmer.time_step;
  result.initial_parameters = function->initial_parameters();
  const auto start = Clock::now();
  switch (settings.optimizer) {
    case ControlOptimizer::kAdam:
      result.final_parameters = MinimizeWithAdam(function.get(), kLoss, settings.adam, &budget);
      break;
    case ControlOptimizer::kLbfgs:
#if DIFFPD_WITH_CERES
      result.final_parameters = MinimizeWithLbfgs(function.get(), kLoss, &budget, &result.optimizer_report);
#endif
      break;
    case ControlOptimizer::kIpopt:
#if DIFFPD_WITH_IPOPT
      // The NLP takes the function over; the final controller gets a new one.
      result.final_parameters = MinimizeWithIpopt(std::move(function), kLoss, &budget, &result.optimizer_report);
      function = MakeSwimmerFunction(swimmer, options, settings.seed);
#endif
      break;
  }
  budget.Finish();
  result.history = budget.history();
  result.failed_evaluations = budget.failed();
  // The final controller (a cache hit where the optimiser ended at a point it evaluated).
  TrainingEvaluation last;
  last.evaluation = static_cast<int>(result.history.size());
  last.simulated_steps = static_cast<long>(budget.used()) * swimmer.steps;
  const auto t0 = Clock::now();
  VectorXd value;
  if (!function->Evaluate(result.final_parameters, function->RowsOf(kLoss), &value, nullptr))
    throw SolverError(SolverStatus::kNonFinite, "the final controller's rollout: " + function->statistics().last_error);
  last.forward_seconds = Seconds(t0);
  last.reward = -value(0);
  if (settings.log)
    std::fprintf(settings.log, "%5d %9ld %14.6f %10.3f %10.3f %12s\n", last.evaluation, last.simulated_steps,
                 last.reward, last.forward_seconds, 0.0, "final");
  result.history.push_back(last);
  result.final_rollout = *function->RolloutAt(result.final_parameters);
  result.total_seconds = Seconds(start);
  return result;
}

std::vector<EvaluationTiming> TimeEvaluations(const Swimmer& swimmer, const SolverOptions& options_in,
                                              const std::vector<Method>& methods, int repeats, std::uint64_t seed) {
  if (repeats < 1) {
    std::ostringstream msg;
    msg << "repeats = " << repeats << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
  const StripNetworkController controller = MakeSwimmerController(swimmer, seed);
  std::vector<std::unique_ptr<Simulator>> sims;
  for (const Method m : methods) {
    SolverOptions o = options_in;
    o.method = m;
    o.time_step = swimmer.time_step;
    sims.push_back(std::make_unique<Simulator>(swimmer.scene, o));
  }
  std::vector<std::vector<double>> forward(methods.size()), backward(methods.size());
  std::vector<EvaluationTiming> out(methods.size());
  for (int r = 0; r < repeats; ++r)
    for (size_t m = 0; m < methods.size(); ++m) {
      Simulator& sim = *sims[m];
      auto t0 = Clock::now();
      const Rollout rollout = sim.Simulate(sim.RestState(), controller, swimmer.steps);
      forward[m].push_back(Seconds(t0));
      LossGradient grad;
      out[m].reward = -swimmer.loss.Evaluate(rollout, &grad);
      t0 = Clock::now();
      sim.Backward(rollout, grad, controller);
      backward[m].push_back(Seconds(t0));
    }
  for (size_t m = 0; m < methods.size(); ++m) {
    out[m].method = methods[m];
    out[m].forward_seconds = Median(forward[m]);
    out[m].backward_seconds = Median(backward[m]);
    out[m].repeats = repeats;
  }
  return out;
}

std::vector<std::string> PlotLearningCurves(const std::string& dir, const std::string& title,
                                            const std::vector<const TrainingResult*>& results,
                                            const std::vector<ReferenceCurve>& references) {
  std::filesystem::create_directories(dir);
  std::vector<std::string> files;
  std::vector<std::pair<std::string, std::string>> series;  // (label, .dat)
  auto write = [&](const std::string& stem, const std::vector<std::pair<double, double>>& points) {
    const std::string path = (std::filesystem::path(dir) / (stem + ".dat")).string();
    std::ofstream out(path);
    if (!out) throw InvalidInputError("cannot write '" + path + "'");
    out.precision(17);
    out << "# simulated_steps reward\n";
    // Log x: the first point (0 steps) sits at 1 step.
    for (const auto& [x, y] : points) out << std::max(x, 1.0) << " " << y << "\n";
    files.push_back(path);
    return path;
  };
  for (const TrainingResult* result : results) {
    std::vector<std::pair<double, double>> own;
    for (const TrainingEvaluation& e : result->history) own.emplace_back(e.simulated_steps, e.reward);
    series.emplace_back("this library, " + result->optimizer + " + " + ToString(result->method),
                        write(results.size() == 1 ? "learning_curve" : "learning_curve_" + result->optimizer, own));
  }
  for (size_t r = 0; r < references.size(); ++r)
    series.emplace_back(references[r].label, write("reference_" + std::to_string(r), references[r].points));
  const std::string png = (std::filesystem::path(dir) / "learning_curve.png").string();
  FILE* gp = popen("gnuplot 2>/dev/null", "w");
  if (!gp) {
    std::fprintf(stderr, "diffpd: gnuplot could not be started; no plot written\n");
    return files;
  }
  std::fprintf(gp, "set terminal pngcairo size 900,540\nset output %s\n", GnuplotQuoted(png).c_str());
  std::fprintf(gp, "set title %s\nset xlabel 'simulated steps'\nset ylabel 'reward'\nset grid\n",
               GnuplotQuoted(title).c_str());
  std::fprintf(gp, "set logscale x\nset key bottom right\nplot ");
  for (size_t i = 0; i < series.size(); ++i)
    std::fprintf(gp, "%s%s using 1:2 with lines lw %d title %s", i ? ", " : "", GnuplotQuoted(series[i].second).c_str(),
                 i < results.size() ? 3 : 1, GnuplotQuoted(series[i].first).c_str());
  std::fprintf(gp, "\n");
  const int status = pclose(gp);
  if (status != 0 || !std::filesystem::exists(png)) {
    std::fprintf(stderr, "diffpd: gnuplot failed (status %d); no plot written\n", status);
    return files;
  }
  files.push_back(png);
  return files;
}

std::string WriteRolloutFrames(const std::string& dir, const std::string& name, const Mesh& mesh,
                               const Rollout& rollout) {
  PvdWriter pvd(dir, name);
  const int nodes = mesh.num_vertices();
  for (size_t k = 0; k < rollout.states.size(); ++k) {
    const State& s = rollout.states[k];
    const VtkPointData data = {{"velocity", Eigen::Map<const Eigen::Matrix3Xd>(s.v.data(), 3, nodes)}};
    pvd.AddFrame(k * rollout.options.time_step, mesh, Eigen::Map<const Eigen::Matrix3Xd>(s.x.data(), 3, nodes), data);
  }
  pvd.Write();
  return (std::filesystem::path(dir) / (name + ".pvd")).string();
}

nlohmann::json TrainingJson(const TrainingResult& r) {
  nlohmann::json curve = nlohmann::json::array();
  for (const TrainingEvaluation& e : r.history)
    curve.push_back({{"evaluation", e.evaluation},
                     {"simulated_steps", e.simulated_steps},
                     {"reward", e.reward},
                     {"forward_s", e.forward_seconds},
                     {"backward_s", e.backward_seconds},
                     {"gradient_norm", e.gradient_norm}});
  return {{"optimizer", r.optimizer},
          {"optimizer_report", r.optimizer_report},
          {"failed_evaluations", r.failed_evaluations},
          {"method", ToString(r.method)},
          {"dofs", r.dofs},
          {"steps", r.steps},
          {"time_step", r.time_step},
          {"parameters", r.parameters},
          {"evaluations", static_cast<int>(r.history.size()) - 1},
          {"initial_reward", r.initial_reward()},
          {"final_reward", r.final_reward()},
          {"best_reward", r.best_reward()},
          {"forward_s_per_evaluation", r.mean_forward_seconds()},
          {"backward_s_per_evaluation", r.mean_backward_seconds()},
          {"total_s", r.total_seconds},
          {"learning_curve", curve}};
}

nlohmann::json TimingJson(const std::vector<EvaluationTiming>& timings) {
  nlohmann::json rows = nlohmann::json::array();
  for (const EvaluationTiming& t : timings)
    rows.push_back({{"method", ToString(t.method)},
                    {"forward_s", t.forward_seconds},
                    {"backward_s", t.backward_seconds},
                    {"evaluation_s", t.forward_seconds + t.backward_seconds},
                    {"reward", t.reward},
                    {"repeats", t.repeats}});
  return rows;
}

SolverOptions SwimmerControl::BaseOptions(bool small) const {
  // The original's step tolerances (rel 1e-3, abs 1e-4 N, at most 1000
  // iterations); adjoint solves to 1e-6 (the training needs no more).
  SolverOptions o;
  o.method = Method::kPdLbfgs;
  o.rel_tolerance = 1e-3;
  o.abs_tolerance = 1e-4;
  o.max_iterations = 1000;
  o.backward_rel_tolerance = 1e-6;
  return o;
}

int SwimmerControl::Run(const CommandArgs& args) const {
  if (args.steps > 0 || args.dt > 0)
    throw InvalidInputError("--steps and --dt are fixed by the control problem '" + name() +
                            "'; use --small for the reduced instance");
  const bool small = args.small;
  std::vector<ControlOptimizer> optimizers = {ControlOptimizer::kAdam};
  if (args.optimizer == "all") {
    optimizers.clear();
    for (const ControlOptimizer o : {ControlOptimizer::kAdam, ControlOptimizer::kLbfgs, ControlOptimizer::kIpopt})
      if (ControlOptimizerAvailable(o)) optimizers.push_back(o);
  } else if (!args.optimizer.empty()) {
    optimizers = {ParseControlOptimizer(args.optimizer)};
  }
  const Swimmer swimmer = MakeSwimmer(small);
  SolverOptions options = BaseOptions(small);
  options.method = args.method;
  options.num_threads = args.threads;
  if (args.rel_tolerance > 0) options.rel_tolerance = args.rel_tolerance;
  options.lbfgs_weight_scale = args.lbfgs_weight_scale;
  options.rigid_mode_correction = args.rigid_mode_correction;
  options.verbosity = args.verbosity;
  options.Validate();
  TrainingSettings settings;
  settings.evaluations = args.evaluations > 0 ? args.evaluations : small ? small_evaluations() : 100;
  if (args.seed >= 0) settings.seed = static_cast<std::uint64_t>(args.seed);
  FILE* text = args.json ? stderr : stdout;
  settings.log = text;

  std::vector<TrainingResult> results;
  nlohmann::json runs = nlohmann::json::array();
  for (const ControlOptimizer optimizer : optimizers) {
    settings.optimizer = optimizer;
    std::fprintf(text, "# %s%s: %d DoFs, %zu muscles in %zu strips, %d steps of %g s, method %s, %s, %d evaluations\n",
                 name().c_str(), small ? " (small)" : "", swimmer.scene.mesh.num_dofs(), swimmer.scene.muscles.size(),
                 swimmer.strips.size(), swimmer.steps, swimmer.time_step, ToString(options.method),
                 ToString(settings.optimizer), settings.evaluations);
    std::fprintf(text, "%5s %9s %14s %10s %10s %12s\n", "eval", "steps", "reward", "forward_s", "backward_s",
                 "|dL/dtheta|");
    results.push_back(TrainSwimmer(swimmer, options, settings));
    const TrainingResult& result = results.back();
    std::fprintf(text,
                 "# %s: reward %.6f -> %.6f (best %.6f); %.3f s forward + %.3f s backward per evaluation, %.1f s "
                 "total\n",
                 result.optimizer.c_str(), result.initial_reward(), result.final_reward(), result.best_reward(),
                 result.mean_forward_seconds(), result.mean_backward_seconds(), result.total_seconds);
    if (!result.optimizer_report.empty()) std::fprintf(text, "# %s\n", result.optimizer_report.c_str());
    runs.push_back(TrainingJson(result));
  }

  nlohmann::json summary = runs.size() == 1 ? runs[0] : nlohmann::json{{"runs", runs}};
  summary["problem"] = name();
  summary["instance"] = small ? "small" : "full";
  summary["seed"] = settings.seed;
  if (args.compare_newton && options.method != Method::kNewtonCholesky && options.method != Method::kNewtonPcg) {
    const int repeats = small ? 1 : 3;
    const std::vector<EvaluationTiming> timings = TimeEvaluations(
        swimmer, options, {options.method, Method::kNewtonCholesky, Method::kNewtonPcg}, repeats, settings.seed);
    const auto seconds = [](const EvaluationTiming& t) { return t.forward_seconds + t.backward_seconds; };
    const EvaluationTiming& best_newton = seconds(timings[1]) <= seconds(timings[2]) ? timings[1] : timings[2];
    const double ratio = seconds(best_newton) / seconds(timings[0]);
    for (const EvaluationTiming& t : timings)
      std::fprintf(text, "# %s: %.3f s forward + %.3f s backward per evaluation (median of %d), reward %.6f\n",
                   ToString(t.method), t.forward_seconds, t.backward_seconds, t.repeats, t.reward);
    std::fprintf(text, "# best Newton (%s) / %s time per evaluation: %.2f\n", ToString(best_newton.method),
                 ToString(options.method), ratio);
    summary["timings"] = TimingJson(timings);
    summary["best_newton"] = ToString(best_newton.method);
    summary["newton_time_ratio"] = ratio;
  }
  const std::string dir = args.out_dir.empty() ? (std::filesystem::path("out") / name()).string() : args.out_dir;
  std::vector<std::string> files;
  std::vector<ReferenceCurve> references;
  for (const auto& [suffix, label] : {std::pair{"diffpd", "original DiffPD (Adam)"}, {"ppo", "original PPO"}}) {
    try {
      references.push_back(ReadReferenceCurve(
          SharedDataPath("paper/learning_curves/" + reference_stem() + "_" + suffix + ".csv"), label));
    } catch (const InvalidInputError& e) {
      std::fprintf(stderr, "diffpd: no reference curve: %s\n", e.what());
    }
  }
  std::vector<const TrainingResult*> curves;
  for (const TrainingResult& r : results) curves.push_back(&r);
  for (const std::string& f : PlotLearningCurves(dir, name() + ": reward per simulated step", curves, references))
    files.push_back(f);
  for (const TrainingResult& r : results) {
    const std::string frames = results.size() == 1 ? "frames" : "frames_" + r.optimizer;
    files.push_back(WriteRolloutFrames((std::filesystem::path(dir) / frames).string(), name(), swimmer.scene.mesh,
                                       r.final_rollout));
  }
  const std::string json_path = (std::filesystem::path(dir) / "summary.json").string();
  std::ofstream(json_path) << summary.dump(2) << "\n";
  files.push_back(json_path);
  for (const std::string& f : files) std::fprintf(text, "# wrote %s\n", f.c_str());
  if (args.json) std::printf("%s\n", summary.dump(2).c_str());
  bool improved = true;
  for (const TrainingResult& r : results) improved = improved && r.final_reward() > r.initial_reward();
  return improved ? 0 : 5;
}

}  // namespace diffpd::problems
