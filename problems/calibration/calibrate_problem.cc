#include "calibration/calibrate_problem.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <ceres/ceres.h>

#include "calibration/iteration_table.h"
#include "calibration/material_fit_settings.h"
#include "cli/commands.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/ceres/rollout_cost_function.h"
#include "diffpd/solvers/ceres/rollout_evaluation_callback.h"
#include "diffpd/solvers/core/marker_residuals.h"
#include "diffpd/vtk_writer.h"

#ifndef DIFFPD_PROJECT_DATA_DIR
#define DIFFPD_PROJECT_DATA_DIR "data"
#endif

namespace diffpd::problems {
namespace {

using solvers::MaterialField;

double Value(const MaterialParameters& m, MaterialField p) {
  switch (p) {
    case MaterialField::kYoungsModulus:
      return m.youngs_modulus;
    case MaterialField::kPoissonsRatio:
      return m.poissons_ratio;
    case MaterialField::kDensity:
      return m.density;
  }
  return 0;
}

std::string Stem(const std::string& file) {
  const size_t dot = file.rfind('.');
  return dot == std::string::npos ? file : file.substr(0, dot);
}

// Unweighted RMS over samples of |simulated - captured|.
double MarkerRmse(const MarkerObservations& obs, const std::vector<State>& states) {
  double sum = 0;
  for (int s = 0; s < obs.num_samples(); ++s) sum += (obs.Simulated(s, states) - obs.captured(s)).squaredNorm();
  return obs.num_samples() ? std::sqrt(sum / obs.num_samples()) : 0;
}

std::string Quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// markers.csv (captured and simulated positions at the capture times),
// marker_paths.csv (simulated positions at every step) and markers.png
// (gnuplot): displacements from the rest position, per axis, per marker.
void WriteMarkerPlot(const std::string& dir, const std::string& title, const CapturedMotion& motion,
                     const MarkerObservations& obs, const std::vector<State>& states, const Mesh& mesh, double h,
                     FILE* log) {
  std::vector<Marker> markers = motion.markers;
  std::sort(markers.begin(), markers.end(), [](const Marker& a, const Marker& b) { return a.id < b.id; });
  std::vector<Vec3> rest(markers.size(), Vec3::Zero());
  std::vector<std::vector<std::pair<int, double>>> stencils;
  for (size_t m = 0; m < markers.size(); ++m) {
    stencils.push_back(MarkerStencil(markers[m], mesh));
    for (const auto& [node, w] : stencils.back()) rest[m] += w * mesh.vertices.col(node);
  }
  const std::string csv = (std::filesystem::path(dir) / "markers.csv").string();
  const std::string paths = (std::filesystem::path(dir) / "marker_paths.csv").string();
  std::ofstream out(csv), path_out(paths);
  if (!out) throw InvalidInputError("cannot write '" + csv + "'");
  if (!path_out) throw InvalidInputError("cannot write '" + paths + "'");
  out << "# one block per marker: time (s), marker, captured x y z (m), simulated x y z (m), rest x y z (m)\n";
  path_out << "# one block per marker: time (s), marker, simulated x y z (m), rest x y z (m)\n";
  char line[320];
  for (size_t m = 0; m < markers.size(); ++m) {
    const Vec3& r = rest[m];
    for (int s = 0; s < obs.num_samples(); ++s) {
      if (obs.marker(s) != markers[m].id) continue;
      const Vec3 sim = obs.Simulated(s, states);
      const Vec3& cap = obs.captured(s);
      std::snprintf(line, sizeof line, "%.6f %d %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", obs.time(s),
                    markers[m].id, cap(0), cap(1), cap(2), sim(0), sim(1), sim(2), r(0), r(1), r(2));
      out << line;
    }
    for (size_t k = 0; k < states.size(); ++k) {
      Vec3 p = Vec3::Zero();
      for (const auto& [node, w] : stencils[m]) p += w * states[k].x.segment<3>(3 * node);
      std::snprintf(line, sizeof line, "%.6f %d %.9g %.9g %.9g %.9g %.9g %.9g\n", k * h, markers[m].id, p(0), p(1),
                    p(2), r(0), r(1), r(2));
      path_out << line;
    }
    out << "\n\n";
    path_out << "\n\n";
  }
  out.close();
  path_out.close();
  const std::string png = (std::filesystem::path(dir) / "markers.png").string();
  std::ostringstream gp;
  gp << "set terminal pngcairo size 1500,520 font ',10'\nset output " << Quote(png) << "\n"
     << "set multiplot layout 1,3 title " << Quote(title + ": captured markers (points) vs fitted simulation (lines)")
     << "\nset xlabel 'time (s)'\nset grid\nset key outside bottom center horizontal\n";
  const char* axes[3] = {"x", "y", "z"};
  for (int d = 0; d < 3; ++d) {
    gp << "set ylabel '" << axes[d] << " displacement (mm)'\nplot ";
    for (size_t m = 0; m < markers.size(); ++m) {
      gp << (m ? ", " : "") << Quote(csv) << " index " << m << " using 1:(($" << 3 + d << "-$" << 9 + d
         << ")*1000) with points pt 7 ps 0.8 lc " << m + 1 << " title 'marker " << markers[m].id << "', "
         << Quote(paths) << " index " << m << " using 1:(($" << 3 + d << "-$" << 6 + d << ")*1000) with lines lw 2 lc "
         << m + 1 << " notitle";
    }
    gp << "\n";
  }
  gp << "unset multiplot\n";
  std::filesystem::remove(png);
  FILE* pipe = popen("gnuplot 2>&1", "w");
  int status = -1;
  if (pipe) {
    std::fputs(gp.str().c_str(), pipe);
    status = pclose(pipe);
  }
  if (status != 0 || !std::filesystem::exists(png)) {
    if (log)
      std::fprintf(log, "# note: gnuplot could not write %s (is gnuplot installed?); the data is in %s\n", png.c_str(),
                   csv.c_str());
  } else if (log) {
    std::fprintf(log, "# wrote %s, %s and %s\n", csv.c_str(), paths.c_str(), png.c_str());
  }
}

}  // namespace

SolverOptions CalibrationProblem::FitOptions(Method method) const {
  SolverOptions options;
  options.method = method;
  options.time_step = default_time_step();
  options.rel_tolerance = 1e-4;
  options.abs_tolerance = 1e-9;
  options.max_iterations = 20000;
  options.backward_rel_tolerance = 1e-8;
  return options;
}

int CalibrationProblem::default_steps() const {
  CapturedMotion motion;
  const std::vector<double> times = CaptureTimes();
  motion.samples.push_back(MarkerSample{times.empty() ? 0.0 : times.back(), 0, Vec3::Zero(), Vec3::Ones(), 0});
  return MarkerObservations::RequiredSteps(motion, default_time_step());
}

Rollout CalibrationProblem::TruthRollout() const {
  Scene scene = MakeScene();
  scene.material = truth();
  SolverOptions options;
  options.method = Method::kNewtonCholesky;
  options.time_step = default_time_step();
  options.rel_tolerance = 1e-11;
  options.abs_tolerance = 1e-11;
  options.num_threads = 1;
  Simulator sim(scene, options);
  return sim.Simulate(InitialState(sim), Inputs(sim, default_steps()));
}

CapturedMotion CalibrationProblem::Sample(const Rollout& truth_rollout, bool clean) const {
  const Mesh mesh = MakeScene().mesh;
  return SampleMarkers(mesh, truth_rollout.states, default_time_step(), Markers(mesh), CaptureTimes(),
                       clean ? 0.0 : noise(), seed());
}

CapturedMotion CalibrationProblem::Synthesize(bool clean) const { return Sample(TruthRollout(), clean); }

std::vector<std::string> CalibrationProblem::WriteSyntheticData(const std::string& dir) const {
  std::filesystem::create_directories(dir);
  std::vector<std::string> paths;
  const MaterialParameters t = truth();
  const Rollout truth_rollout = TruthRollout();
  for (bool clean : {false, true}) {
    const std::string path =
        (std::filesystem::path(dir) / (clean ? Stem(data_file()) + "_clean.csv" : data_file())).string();
    std::ostringstream comment;
    comment << "Synthetic captured motion of the diffpd problem '" << name() << "': " << description() << "\n"
            << "Generated by `diffpd synth " << name() << " --dir " << dir << "` (CalibrationProblem::Synthesize):\n"
            << "true material E = " << t.youngs_modulus << " Pa, nu = " << t.poissons_ratio << ", rho = " << t.density
            << " kg/m^3; newton-cholesky, h = " << default_time_step() << " s, " << default_steps()
            << " steps, relative tolerance 1e-11;\n"
            << "positions interpolated linearly in time at the capture times, ";
    if (clean)
      comment << "no noise.";
    else
      comment << "plus Gaussian noise of standard deviation " << noise() << " m on every coordinate (seed " << seed()
              << ", std::mt19937_64 and Box-Muller).";
    WriteCapturedMotion(path, Sample(truth_rollout, clean), comment.str());
    paths.push_back(path);
  }
  return paths;
}

std::string CalibrationProblem::DefaultDataPath() const {
  const char* env = std::getenv("DIFFPD_DATA");
  const std::string dir = env && *env ? env : DIFFPD_PROJECT_DATA_DIR;
  return (std::filesystem::path(dir) / data_file()).lexically_normal().string();
}

std::unique_ptr<solvers::RolloutFunction> CalibrationProblem::MakeModel(const CapturedMotion& motion,
                                                                        const SolverOptions& solver) const {
  Scene scene = MakeScene();
  scene.material = initial_guess();
  const int steps = MarkerObservations::RequiredSteps(motion, solver.time_step);
  auto function = std::make_unique<solvers::RolloutFunction>(scene, solver, steps);
  function->SetInitialState(InitialState(function->simulator()));
  function->SetInputs(Inputs(function->simulator(), steps));
  const std::vector<MaterialField> fields = fitted();
  function->AddBlock(std::make_unique<solvers::MaterialBlock>(
      std::vector<solvers::MaterialBlock::Entry>(fields.begin(), fields.end()), scene));
  function->AddFunctional(std::make_unique<solvers::MarkerResiduals>(motion, scene.mesh, solver.time_step, steps));
  return function;
}

CalibrationFit CalibrationProblem::Fit(const CapturedMotion& motion, Method method, int max_iterations,
                                       FILE* log) const {
  return Fit(motion, FitOptions(method), max_iterations, log);
}

CalibrationFit CalibrationProblem::Fit(const CapturedMotion& motion, const SolverOptions& solver, int max_iterations,
                                       FILE* log) const {
  const auto start = std::chrono::steady_clock::now();
  const Method method = solver.method;
  SolverOptions simulation = solver;
  simulation.time_step = default_time_step();
  const std::unique_ptr<solvers::RolloutFunction> model = MakeModel(motion, simulation);
  solvers::RolloutFunction& function = *model;
  const std::vector<MaterialField> fields = fitted();
  constexpr int markers = 0;
  CalibrationFit fit;
  fit.method = method;
  fit.fitted = fields;
  const VectorXd start_values = function.initial_parameters();
  std::vector<double> block(start_values.data(), start_values.data() + start_values.size());
  fit.initial = block;

  solvers::RolloutEvaluationCallback callback(&function, {block.data()});
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &callback;
  ceres::Problem problem(problem_options);
  const size_t frames = solvers::AddMarkerResidualBlocks(&problem, &function, markers, {block.data()}).size();
  SetMaterialCoordinates(&problem, block.data(), fields);
  ceres::Solver::Options options = MaterialFitOptions(max_iterations);
  IterationTable table(log, fields, block.data());
  if (log) {
    options.callbacks.push_back(&table);
    std::fprintf(
        log,
        "# fit with %s: Levenberg-Marquardt on log E and nu in [0.01, 0.49]; %zu residual blocks (one per frame)\n",
        ToString(method), frames);
  }
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  fit.values = block;
  fit.initial_cost = summary.initial_cost;
  fit.final_cost = summary.final_cost;
  fit.iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit.usable = summary.IsSolutionUsable() && summary.termination_type != ceres::FAILURE;
  fit.termination = summary.message;
  if (!std::isfinite(summary.final_cost)) {  // Ceres "converges" on a cost that stays inf
    fit.usable = false;
    fit.termination += "; the cost is not finite";
  }
  const Rollout* rollout = function.RolloutAt(Eigen::Map<const VectorXd>(block.data(), block.size()));
  if (rollout) {
    fit.rollout = *rollout;
    const auto& residuals = dynamic_cast<const solvers::MarkerResiduals&>(function.functional(markers));
    fit.marker_rmse_m = MarkerRmse(residuals.observations(), fit.rollout.states);
  } else {
    fit.usable = false;
  }
  fit.statistics = function.statistics();
  fit.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return fit;
}

nlohmann::json CalibrationProblem::Report(const std::vector<CalibrationFit>& fits, const std::string& data_path) const {
  nlohmann::json out;
  out["problem"] = name();
  out["data_file"] = data_path;
  const MaterialParameters t = truth();
  nlohmann::json truth_json, fits_json = nlohmann::json::array();
  for (MaterialField p : fitted()) truth_json[ToString(p)] = Value(t, p);
  for (const CalibrationFit& f : fits) {
    nlohmann::json j;
    j["method"] = ToString(f.method);
    for (size_t i = 0; i < f.fitted.size(); ++i) {
      j[ToString(f.fitted[i])] = f.values[i];
      j[std::string(ToString(f.fitted[i])) + "_relative_error"] =
          std::abs(f.values[i] - Value(t, f.fitted[i])) / std::abs(Value(t, f.fitted[i]));
    }
    j["initial_cost"] = f.initial_cost;
    j["final_cost"] = f.final_cost;
    j["marker_rmse_mm"] = 1e3 * f.marker_rmse_m;
    j["iterations"] = f.iterations;
    j["evaluations"] = f.statistics.rollouts;
    j["jacobian_evaluations"] = f.statistics.jacobians;
    j["failed_evaluations"] = f.statistics.failures;
    j["forward_seconds"] = f.statistics.forward_seconds;
    j["backward_seconds"] = f.statistics.backward_seconds;
    j["total_seconds"] = f.total_seconds;
    j["usable"] = f.usable;
    j["termination"] = f.termination;
    fits_json.push_back(j);
  }
  if (!fits.empty()) {
    const CalibrationFit& main = fits.front();
    for (size_t i = 0; i < main.fitted.size(); ++i) out[ToString(main.fitted[i])] = main.values[i];
    out["method"] = ToString(main.method);
    out["final_cost"] = main.final_cost;
    out["marker_rmse_mm"] = 1e3 * main.marker_rmse_m;
    out["evaluations"] = main.statistics.rollouts;
    out["forward_seconds"] = main.statistics.forward_seconds;
    out["backward_seconds"] = main.statistics.backward_seconds;
  }
  out["truth"] = truth_json;
  out["noise_m"] = noise();
  out["fits"] = fits_json;
  return out;
}

int CalibrationProblem::Run(const CommandArgs& args) const {
  if (args.steps > 0 || args.dt > 0)
    throw InvalidInputError("--steps and --dt are fixed by the captured motion of " + name());
  RefuseSimulatorTuning(args, name());
  FILE* log = args.json ? stderr : stdout;
  const std::string data_path = args.data_file.empty() ? DefaultDataPath() : args.data_file;
  const CapturedMotion motion = ReadCapturedMotion(data_path);
  std::vector<Method> methods;
  for (const std::string& m : args.methods) methods.push_back(ParseMethod(m));
  if (methods.empty()) methods = default_methods();
  if (!args.compare_newton) methods.resize(1);
  const int iterations = args.max_iterations > 0 ? args.max_iterations : max_iterations();
  const Scene scene = MakeScene();
  const MaterialParameters t = truth(), guess = initial_guess();
  std::fprintf(log, "# %s: %s\n", name().c_str(), description().c_str());
  std::fprintf(log, "# mesh: %d nodes, %d %s elements, %d DoFs; h = %g s, %d steps\n", scene.mesh.num_vertices(),
               scene.mesh.num_elements(), ToString(scene.mesh.type), scene.mesh.num_dofs(), default_time_step(),
               default_steps());
  std::fprintf(log, "# captured motion: %s (%zu markers, %zu samples)\n", data_path.c_str(), motion.markers.size(),
               motion.samples.size());
  std::fprintf(log, "# fitting");
  for (MaterialField p : fitted())
    std::fprintf(log, " %s (start %g, truth %g)", ToString(p), Value(guess, p), Value(t, p));
  std::fprintf(log, "\n");

  std::vector<CalibrationFit> fits;
  for (Method method : methods) {
    std::fprintf(log, "\n");
    fits.push_back(Fit(motion, method, iterations, log));
    const CalibrationFit& f = fits.back();
    std::fprintf(log, "# %s: %s after %d iterations, %.2f s\n", ToString(method), f.termination.c_str(), f.iterations,
                 f.total_seconds);
  }

  std::fprintf(log, "\n# recovered vs true parameters\n%-16s", "method");
  for (MaterialField p : fitted()) std::fprintf(log, " %14s %10s", ToString(p), "rel_err");
  std::fprintf(log, " %14s\n%-16s", "marker_rmse_mm", "truth");
  for (MaterialField p : fitted()) std::fprintf(log, " %14.6g %10s", Value(t, p), "");
  std::fprintf(log, "\n");
  for (const CalibrationFit& f : fits) {
    std::fprintf(log, "%-16s", ToString(f.method));
    for (size_t i = 0; i < f.fitted.size(); ++i)
      std::fprintf(log, " %14.6g %9.3f%%", f.values[i],
                   100 * std::abs(f.values[i] - Value(t, f.fitted[i])) / std::abs(Value(t, f.fitted[i])));
    std::fprintf(log, " %14.4f\n", 1e3 * f.marker_rmse_m);
  }
  std::fprintf(log, "# (the shipped data carries %g mm of noise per coordinate; marker RMSE is over samples)\n",
               1e3 * noise());
  std::fprintf(log, "\n# the paper's columns (Sec. 7.1)\n%-16s %10s %10s %12s %14s %10s\n", "method", "forward_s",
               "backward_s", "evaluations", "final_loss", "total_s");
  for (const CalibrationFit& f : fits)
    std::fprintf(log, "%-16s %10.2f %10.2f %12ld %14.6e %10.2f\n", ToString(f.method), f.statistics.forward_seconds,
                 f.statistics.backward_seconds, f.statistics.rollouts, f.final_cost, f.total_seconds);
  std::fprintf(log, "# evaluations: rollouts (distinct parameter values); backward: forward-mode Jacobians\n");

  const nlohmann::json report = Report(fits, data_path);
  if (!args.out_dir.empty() && !fits.empty() && !fits.front().rollout.states.empty()) {
    std::filesystem::create_directories(args.out_dir);
    const CalibrationFit& f = fits.front();
    PvdWriter pvd(args.out_dir, name() + "_fitted");
    const Eigen::Matrix3Xd rest = scene.mesh.vertices;
    for (size_t k = 0; k < f.rollout.states.size(); ++k) {
      const Eigen::Map<const Eigen::Matrix3Xd> x(f.rollout.states[k].x.data(), 3, scene.mesh.num_vertices());
      pvd.AddFrame(k * default_time_step(), scene.mesh, x, {{"displacement", x - rest}});
    }
    pvd.Write();
    std::fprintf(log, "\n# wrote the fitted trajectory (%s) to %s/%s_fitted.pvd\n", ToString(f.method),
                 args.out_dir.c_str(), name().c_str());
    const MarkerObservations obs(motion, scene.mesh, default_time_step(), f.rollout.num_steps());
    WriteMarkerPlot(args.out_dir, name(), motion, obs, f.rollout.states, scene.mesh, default_time_step(), log);
    std::ofstream(std::filesystem::path(args.out_dir) / "calibration.json") << report.dump(2) << "\n";
  }
  if (args.json) std::printf("%s\n", report.dump(2).c_str());
  int status = 0;
  for (const CalibrationFit& f : fits)
    if (!f.usable) {
      std::fprintf(stderr, "diffpd: %s: the %s fit is not usable (%s; final cost %g)\n", name().c_str(),
                   ToString(f.method), f.termination.c_str(), f.final_cost);
      status = 5;
    }
  return status;
}

}  // namespace diffpd::problems
