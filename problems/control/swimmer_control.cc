#include "control/swimmer_control.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/commands.h"
#include "diffpd/error.h"
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

double SwimLoss::Evaluate(const Rollout& rollout, LossGradient* grad) const {
  DIFFPD_CHECK(!nodes.empty(), "SwimLoss: no nodes");
  const int steps = rollout.num_steps();
  const int n = static_cast<int>(rollout.states[0].v.size());
  if (grad) *grad = LossGradient(steps);
  const double share = 1.0 / static_cast<double>(nodes.size());
  double loss = 0;
  for (int k = 1; k <= steps; ++k) {
    const VectorXd& v = rollout.states[k].v;
    Vec3 mean = Vec3::Zero();
    for (const int i : nodes) mean += v.segment<3>(3 * i);
    mean *= share;
    const double forward = direction.dot(mean);
    const Vec3 side = mean - forward * direction;
    loss += -forward + side_weight * side.squaredNorm();
    if (!grad) continue;
    // dL/dvbar = -d + 2 w (I - d d^T) side = -d + 2 w side.
    const Vec3 g_mean = -direction + 2 * side_weight * side;
    VectorXd& dv = grad->dv[k];
    dv = VectorXd::Zero(n);
    for (const int i : nodes) dv.segment<3>(3 * i) += share * g_mean;
  }
  return loss;
}

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
  }
  return "";
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

TrainingResult TrainSwimmer(const Swimmer& swimmer, const SolverOptions& options_in, const TrainingSettings& settings) {
  if (settings.evaluations < 1) {
    std::ostringstream msg;
    msg << "evaluations = " << settings.evaluations << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
  SolverOptions options = options_in;
  options.time_step = swimmer.time_step;
  Simulator sim(swimmer.scene, options);
  StripNetworkController controller = MakeSwimmerController(swimmer, settings.seed);
  Adam adam(settings.adam, controller.num_parameters());
  const State initial = sim.RestState();

  TrainingResult result;
  result.optimizer = ToString(settings.optimizer);
  result.method = options.method;
  result.dofs = sim.num_dofs();
  result.steps = swimmer.steps;
  result.parameters = controller.num_parameters();
  result.time_step = swimmer.time_step;
  result.initial_parameters = controller.parameters();
  const auto start = Clock::now();
  VectorXd theta = controller.parameters();
  for (int e = 0; e <= settings.evaluations; ++e) {
    controller.SetParameters(theta);
    TrainingEvaluation row;
    row.evaluation = e;
    row.simulated_steps = static_cast<long>(e) * swimmer.steps;
    auto t0 = Clock::now();
    Rollout rollout = sim.Simulate(initial, controller, swimmer.steps);
    row.forward_seconds = Seconds(t0);
    LossGradient loss_grad;
    const bool last = e == settings.evaluations;
    row.reward = -swimmer.loss.Evaluate(rollout, last ? nullptr : &loss_grad);
    if (!last) {
      t0 = Clock::now();
      const RolloutGradient g = sim.Backward(rollout, loss_grad, controller);
      row.backward_seconds = Seconds(t0);
      row.gradient_norm = g.controller_parameters.norm();
      adam.Step(g.controller_parameters, &theta);
    } else {
      result.final_rollout = std::move(rollout);
    }
    if (settings.log)
      std::fprintf(settings.log, "%5d %9ld %14.6f %10.3f %10.3f %12.4e\n", row.evaluation, row.simulated_steps,
                   row.reward, row.forward_seconds, row.backward_seconds, row.gradient_norm);
    if (settings.log) std::fflush(settings.log);
    result.history.push_back(row);
  }
  result.final_parameters = theta;
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

ReferenceCurve ReadReferenceCurve(const std::string& path, const std::string& label) {
  std::ifstream in(path);
  if (!in) throw InvalidInputError("cannot open '" + path + "'");
  ReferenceCurve curve;
  curve.label = label;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream row(line);
    double x, y;
    if (!(row >> x >> y) || !std::isfinite(x) || !std::isfinite(y)) {
      std::ostringstream msg;
      msg << path << ":" << number << ": expected two finite numbers 'x,y'";
      throw InvalidInputError(msg.str());
    }
    curve.points.emplace_back(x, y);
  }
  if (curve.points.empty()) throw InvalidInputError(path + ": no data rows");
  return curve;
}

std::vector<std::string> PlotLearningCurve(const std::string& dir, const std::string& title,
                                           const TrainingResult& result,
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
  std::vector<std::pair<double, double>> own;
  for (const TrainingEvaluation& e : result.history) own.emplace_back(e.simulated_steps, e.reward);
  series.emplace_back("this library, " + result.optimizer + " + " + ToString(result.method),
                      write("learning_curve", own));
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
                 i == 0 ? 3 : 1, GnuplotQuoted(series[i].first).c_str());
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
  std::fprintf(text, "# %s%s: %d DoFs, %zu muscles in %zu strips, %d steps of %g s, method %s, %s, %d evaluations\n",
               name().c_str(), small ? " (small)" : "", swimmer.scene.mesh.num_dofs(), swimmer.scene.muscles.size(),
               swimmer.strips.size(), swimmer.steps, swimmer.time_step, ToString(options.method),
               ToString(settings.optimizer), settings.evaluations);
  std::fprintf(text, "%5s %9s %14s %10s %10s %12s\n", "eval", "steps", "reward", "forward_s", "backward_s",
               "|dL/dtheta|");
  const TrainingResult result = TrainSwimmer(swimmer, options, settings);
  std::fprintf(text,
               "# reward %.6f -> %.6f (best %.6f); %.3f s forward + %.3f s backward per evaluation, %.1f s total\n",
               result.initial_reward(), result.final_reward(), result.best_reward(), result.mean_forward_seconds(),
               result.mean_backward_seconds(), result.total_seconds);

  nlohmann::json summary = TrainingJson(result);
  summary["problem"] = name();
  summary["instance"] = small ? "small" : "full";
  summary["seed"] = settings.seed;
  if (args.compare_newton && options.method != Method::kNewtonCholesky) {
    const int repeats = small ? 1 : 3;
    const std::vector<EvaluationTiming> timings =
        TimeEvaluations(swimmer, options, {options.method, Method::kNewtonCholesky}, repeats, settings.seed);
    const double ratio = (timings[1].forward_seconds + timings[1].backward_seconds) /
                         (timings[0].forward_seconds + timings[0].backward_seconds);
    for (const EvaluationTiming& t : timings)
      std::fprintf(text, "# %s: %.3f s forward + %.3f s backward per evaluation (median of %d), reward %.6f\n",
                   ToString(t.method), t.forward_seconds, t.backward_seconds, t.repeats, t.reward);
    std::fprintf(text, "# newton-cholesky / %s time per evaluation: %.2f\n", ToString(options.method), ratio);
    summary["timings"] = TimingJson(timings);
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
  for (const std::string& f : PlotLearningCurve(dir, name() + ": reward per simulated step", result, references))
    files.push_back(f);
  files.push_back(WriteRolloutFrames((std::filesystem::path(dir) / "frames").string(), name(), swimmer.scene.mesh,
                                     result.final_rollout));
  const std::string json_path = (std::filesystem::path(dir) / "summary.json").string();
  std::ofstream(json_path) << summary.dump(2) << "\n";
  files.push_back(json_path);
  for (const std::string& f : files) std::fprintf(text, "# wrote %s\n", f.c_str());
  if (args.json) std::printf("%s\n", summary.dump(2).c_str());
  return result.final_reward() > result.initial_reward() ? 0 : 5;
}

}  // namespace diffpd::problems
