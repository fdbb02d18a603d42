#include "calibration/calibrate_starfish.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "calibration/starfish_fit_starts.h"
#include "calibration/starfish_plot.h"
#include "calibration/starfish_trace.h"
#include "cli/commands.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/core/least_squares_loss.h"
#include "diffpd/solvers/core/marker_residuals.h"
#include "diffpd/solvers/core/material_block.h"
#include "diffpd/solvers/core/state_force_block.h"
#include "shared_data.h"

namespace diffpd::problems {
namespace {

constexpr double kMm = 1e-3;
constexpr double kLossScale = 0.002;  // m: residuals in units of 2 mm
constexpr double kFitStart = 1.0;     // s: the tendon first moves at 1.18 s in cyclic1
constexpr double kFitSeconds = 5.0;   // s
constexpr double kDefaultSeconds = 10;
// Levenberg-Marquardt iterations: 20 with the density in the fit (the
// default), 10 without it (docs/benchmarks.md, the cross-validation).
constexpr int kDefaultIterations = 10;
constexpr int kDefaultIterationsWithDensity = 20;
constexpr int kDefaultStarts = 1;
constexpr int kVtkStride = 6;  // camera frames per VTK frame: 10 per second

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// A flag that takes one of two words: whether `value` is `chosen`;
// InvalidInputError naming the flag and both words otherwise.
bool ParseTwoWayOption(const std::string& flag, const std::string& value, const char* first, const char* second,
                       const char* chosen) {
  if (value != first && value != second)
    throw InvalidInputError(flag + " = '" + value + "' is invalid: calibrate-starfish knows '" + first + "' or '" +
                            second + "'");
  return value == chosen;
}

}  // namespace

std::string StarfishCalibration::description() const {
  return "fit E, nu, tendon slack, servo lags and tendon length and the water's drag and thrust of a soft starfish "
         "swimming underwater to real captured motion, predict other recordings";
}

void StarfishCalibration::set_substeps(int substeps) {
  if (substeps < 1 || substeps > 100)
    throw InvalidInputError("substeps = " + std::to_string(substeps) + " is invalid: must be in [1, 100]");
  substeps_ = substeps;
}

Scene StarfishCalibration::MakeScene() const { return MakeStarfishScene(regions_); }

SolverOptions StarfishCalibration::Options(Method method, int threads) const {
  SolverOptions options;
  options.method = method;
  options.time_step = default_time_step();
  options.rel_tolerance = 1e-3;
  options.abs_tolerance = 1e-6;
  options.max_iterations = 5000;
  options.backward_rel_tolerance = 1e-8;
  options.num_threads = threads;
  return options;
}

std::vector<double> StarfishCalibration::WindowContractions(const StarfishRecording& rec,
                                                            const StarfishWindow& w) const {
  std::vector<double> c((w.num_frames() - 1) * substeps_);
  for (size_t i = 0; i < c.size(); ++i) c[i] = rec.tendon[w.first + static_cast<int>(i) / substeps_];
  return c;
}

std::vector<StepInput> StarfishCalibration::WindowInputs(const StarfishRecording& rec, const StarfishWindow& w,
                                                         const StarfishActuation& actuation) const {
  int negative = -1;
  const std::vector<double> a = StarfishActivationsUntilNegative(
      WindowContractions(rec, w), StarfishTimeStep(rec, w, substeps_), actuation, nullptr, &negative);
  if (negative >= 0) {
    const int row = w.first + negative / substeps_;
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[row]) + ": tendon = " +
                            Num(rec.tendon[row] / kMm) + " mm gives " + NegativeActivation(a, negative, actuation));
  }
  std::vector<StepInput> inputs(a.size());
  for (size_t i = 0; i < a.size(); ++i) inputs[i].activation = VectorXd::Constant(4, a[i]);
  return inputs;
}

State StarfishCalibration::WindowInitialState(Simulator& sim, const StarfishRecording& rec, const StarfishWindow& w,
                                              const StarfishActuation& actuation) const {
  State s = sim.RestState();
  int negative = -1;
  const std::vector<double> first =
      StarfishActivationsUntilNegative({rec.tendon[w.first]}, 1, actuation, nullptr, &negative);
  if (negative >= 0)
    throw InvalidInputError(rec.path + ":" + std::to_string(rec.lines[w.first]) + ": tendon = " +
                            Num(rec.tendon[w.first] / kMm) + " mm gives " + NegativeActivation(first, 0, actuation));
  const double a = first[0];
  if (a == 1) return s;
  StepInput input;
  input.activation = VectorXd::Constant(4, a);
  s.x = sim.SolveQuasiStatic(s.x, input);
  return s;
}

CapturedMotion StarfishCalibration::WindowMotion(const Mesh& mesh, const State& initial, const StarfishRecording& rec,
                                                 const StarfishWindow& w) const {
  const std::array<int, 4> vertices = MarkerVertices(mesh);
  const double h = StarfishTimeStep(rec, w, substeps_);
  double total_weight = 0;
  for (double wm : kMarkerWeights) total_weight += wm;
  const int frames = w.num_frames() - 1;
  CapturedMotion motion;
  for (int m = 0; m < 4; ++m) motion.markers.push_back(Marker{m, vertices[m], -1, Vec3::Zero(), 0});
  const std::array<double, 8>& ref = rec.markers[w.first];
  for (int j = w.first + 1; j <= w.last; ++j) {
    for (int m = 0; m < 4; ++m) {
      MarkerSample s;
      s.time = (j - w.first) * substeps_ * h;
      s.marker = m;
      s.position = initial.x.segment<3>(3 * vertices[m]);
      s.position(0) += rec.markers[j][2 * m] - ref[2 * m];
      s.position(2) -= rec.markers[j][2 * m + 1] - ref[2 * m + 1];
      const double weight = std::sqrt(kMarkerWeights[m] / (total_weight * frames)) / kLossScale;
      s.weight = Vec3(weight, 0, weight);
      s.line = rec.lines[j];
      motion.samples.push_back(s);
    }
  }
  motion.Validate(rec.path);  // a problem names the recording's file and row
  return motion;
}

StarfishErrors StarfishCalibration::WindowErrors(const Mesh& mesh, const std::vector<State>& states,
                                                 const StarfishRecording& rec, const StarfishWindow& w) const {
  return CompareDisplacements(SimulatedDisplacements(MarkerVertices(mesh), states, substeps_, w.num_frames()),
                              CapturedDisplacements(rec, w));
}

std::unique_ptr<solvers::RolloutFunction> StarfishCalibration::MakeModel(
    const StarfishRecording& rec, const StarfishWindow& w, const SolverOptions& options,
    const MaterialParameters& material, const StarfishActuation& actuation, const StarfishWater& water,
    const CapturedMotion* motion, double linear_damping) const {
  using solvers::MaterialField;
  Scene scene = MakeScene();
  scene.material = material;
  scene.hydrodynamics->drag_tangential = water.drag_tangential;
  scene.hydrodynamics->drag_normal = water.drag_normal;
  scene.hydrodynamics->thrust = water.thrust;
  for (MaterialRegion& region : scene.material_regions) region.material = material;
  if (damping_in_model()) scene.linear_damping = linear_damping;
  SolverOptions solver = options;
  solver.time_step = StarfishTimeStep(rec, w, substeps_);
  std::vector<StepInput> inputs = WindowInputs(rec, w, actuation);
  const int steps = static_cast<int>(inputs.size());
  State initial;
  {
    Simulator sim(scene, solver);
    initial = WindowInitialState(sim, rec, w, actuation);
  }
  auto model = std::make_unique<solvers::RolloutFunction>(scene, solver, steps);
  model->SetInitialState(initial);
  model->SetInputs(std::move(inputs));
  std::vector<solvers::MaterialBlock::Entry> fitted = {MaterialField::kYoungsModulus, MaterialField::kPoissonsRatio};
  if (density_in_model()) fitted.push_back(MaterialField::kDensity);
  if (regions_ == StarfishRegions::kBodyArms) {
    fitted.push_back({MaterialField::kYoungsModulus, 0});
    fitted.push_back({MaterialField::kPoissonsRatio, 0});
  }
  model->AddBlock(std::make_unique<solvers::MaterialBlock>(fitted, scene));
  model->AddBlock(std::make_unique<TendonActuationBlock>(WindowContractions(rec, w), solver.time_step,
                                                         static_cast<int>(scene.muscles.size()), actuation));
  if (water_in_model()) {
    using solvers::StateForceField;
    model->AddBlock(std::make_unique<solvers::StateForceBlock>(
        std::vector<solvers::StateForceBlock::Entry>{StateForceField::kDragTangential, StateForceField::kDragNormal,
                                                     StateForceField::kThrust},
        scene));
  }
  if (damping_in_model())
    model->AddBlock(std::make_unique<solvers::StateForceBlock>(
        std::vector<solvers::StateForceBlock::Entry>{solvers::StateForceField::kLinearDamping}, scene));
  auto residuals = std::make_unique<solvers::MarkerResiduals>(
      motion ? *motion : WindowMotion(scene.mesh, initial, rec, w), scene.mesh, solver.time_step, steps);
  if (fit_method_ == StarfishFitMethod::kLbfgs)
    model->AddFunctional(std::make_unique<solvers::LeastSquaresLoss>(std::move(residuals)));
  else
    model->AddFunctional(std::move(residuals));
  return model;
}

StarfishFit StarfishCalibration::Fit(const StarfishRecording& rec, const StarfishWindow& w,
                                     const SolverOptions& options, const MaterialParameters& guess,
                                     const StarfishActuation& actuation_guess, int max_iterations, FILE* log,
                                     const StarfishWater& water_guess) const {
  const bool arms = regions_ == StarfishRegions::kBodyArms;
  if (arms && fit_method_ == StarfishFitMethod::kLevenbergMarquardt)
    throw InvalidInputError("the lm fit has no tied arms' nu: fit body-arms regions with --fit lbfgs");
  StarfishActuation start = actuation_guess;
  if (!release_in_model())
    start.release_lag.reset();
  else if (!start.release_lag)
    start.release_lag = start.lag;
  if (water_in_model()) CheckStarfishWaterStart(water_guess);
  const StarfishWater water = water_in_model() ? water_guess : StarfishWater();
  StarfishMassDamping mass_damping;
  mass_damping.fit_density = density_in_model();
  if (damping_in_model()) mass_damping.linear_damping_guess = DampingGuess();
  CheckStarfishMassDampingStart(guess.density, mass_damping);
  std::unique_ptr<solvers::RolloutFunction> model = MakeModel(rec, w, options, guess, start, water);
  if (fit_method_ == StarfishFitMethod::kLevenbergMarquardt)
    return FitStarfishLeastSquares(model.get(), 0, guess, start, water_in_model() ? &water : nullptr, max_iterations,
                                   log, mass_damping);
  return FitStarfishLoss(model.get(), regions_ == StarfishRegions::kBodyArms, guess, start, max_iterations, log);
}

StarfishCalibration::Prediction StarfishCalibration::Predict(const StarfishRecording& rec, const StarfishWindow& w,
                                                             const SolverOptions& options,
                                                             const StarfishFit& fit) const {
  Scene s = MakeScene();
  s.material = fit.material;
  for (size_t r = 0; r < fit.region_materials.size(); ++r) s.material_regions[r].material = fit.region_materials[r];
  s.hydrodynamics->drag_tangential = fit.water.drag_tangential;
  s.hydrodynamics->drag_normal = fit.water.drag_normal;
  s.hydrodynamics->thrust = fit.water.thrust;
  if (fit.linear_damping) s.linear_damping = *fit.linear_damping;
  SolverOptions o = options;
  o.time_step = StarfishTimeStep(rec, w, substeps_);
  Simulator sim(s, o);
  Prediction p;
  const auto t0 = std::chrono::steady_clock::now();
  const State initial = WindowInitialState(sim, rec, w, fit.actuation);
  p.rollout = sim.Simulate(initial, WindowInputs(rec, w, fit.actuation));
  p.simulate_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  p.simulated = SimulatedDisplacements(MarkerVertices(s.mesh), p.rollout.states, substeps_, w.num_frames());
  p.captured = CapturedDisplacements(rec, w);
  p.errors = CompareDisplacements(p.simulated, p.captured);
  p.baselines = BaselineErrors(p.captured);
  return p;
}

int StarfishCalibration::Run(const CommandArgs& args) const {
  RefuseSimulatorTuning(args, name());
  if (!args.regions.empty() || !args.fit.empty() || !args.water.empty() || !args.servo.empty() ||
      !args.density.empty() || !args.damping.empty()) {
    StarfishCalibration with = *this;
    if (!args.regions.empty()) with.set_regions(ParseStarfishRegions(args.regions));
    if (!args.fit.empty()) with.set_fit_method(ParseStarfishFitMethod(args.fit));
    if (!args.water.empty()) with.set_fit_water(ParseTwoWayOption("--water", args.water, "fitted", "fixed", "fitted"));
    if (!args.servo.empty())
      with.set_fit_release_lag(ParseTwoWayOption("--servo", args.servo, "symmetric", "asymmetric", "asymmetric"));
    if (!args.density.empty())
      with.set_fit_density(ParseTwoWayOption("--density", args.density, "fitted", "fixed", "fitted"));
    if (!args.damping.empty())
      with.set_fit_damping(ParseTwoWayOption("--damping", args.damping, "fitted", "fixed", "fitted"));
    CommandArgs rest = args;
    rest.regions.clear();
    rest.fit.clear();
    rest.water.clear();
    rest.servo.clear();
    rest.density.clear();
    rest.damping.clear();
    return with.Run(rest);
  }
  if (args.steps > 0 || args.dt > 0)
    throw InvalidInputError("--steps and --dt are fixed by the recordings of " + name() + " (60 Hz camera frames, " +
                            std::to_string(substeps_) + " steps per frame)");
  if (!args.data_file.empty())
    throw InvalidInputError(name() + " reads its recordings from --calibrate and --predict, not --data");
  const auto start_clock = std::chrono::steady_clock::now();
  FILE* log = args.json ? stderr : stdout;
  const double seconds = args.seconds > 0 ? args.seconds : kDefaultSeconds;
  if (args.seconds != -1 && !(args.seconds > 0))
    throw InvalidInputError("--seconds = " + Num(args.seconds) + " is invalid: must be > 0 (s)");
  std::string calibrate_path = args.calibrate_file;
  std::vector<std::string> predict_paths = args.predict_files;
  if (calibrate_path.empty()) {
    calibrate_path = SharedDataPath("starfish/data_horizontal_cyclic1.csv");
    if (predict_paths.empty()) predict_paths = {calibrate_path, SharedDataPath("starfish/data_horizontal_cyclic2.csv")};
  } else if (predict_paths.empty()) {
    predict_paths = {calibrate_path};
  }
  // pd-lbfgs unless chosen: --methods (first entry) or a --method other than
  // the command line's default (pd).
  const Method method = !args.methods.empty()        ? ParseMethod(args.methods.front())
                        : args.method != Method::kPd ? args.method
                                                     : Method::kPdLbfgs;
  const SolverOptions options = Options(method, args.threads);

  // Read everything first: bad input fails before any simulation.
  const StarfishRecording calibration = ReadStarfishRecording(calibrate_path);
  std::vector<StarfishRecording> predictions;
  for (const std::string& p : predict_paths) predictions.push_back(ReadStarfishRecording(p));
  if (args.fit_start != -1 && !(args.fit_start >= 0))
    throw InvalidInputError("--fit-start = " + Num(args.fit_start) + " is invalid: must be >= 0 (s)");
  if (args.fit_seconds != -1 && !(args.fit_seconds > 0))
    throw InvalidInputError("--fit-seconds = " + Num(args.fit_seconds) + " is invalid: must be > 0 (s)");
  const StarfishWindow fit_window = MakeStarfishWindow(calibration, args.fit_start >= 0 ? args.fit_start : kFitStart,
                                                       args.fit_seconds > 0 ? args.fit_seconds : kFitSeconds);
  std::vector<StarfishWindow> windows;
  for (const StarfishRecording& r : predictions) windows.push_back(MakeStarfishWindow(r, 0, seconds));

  const Scene scene = MakeScene();
  std::fprintf(log, "# %s: %s\n", name().c_str(), description().c_str());
  std::fprintf(log,
               "# mesh: TetGen -%s of starfish_half_simplified.obj: %d nodes, %d tets, %d DoFs (%zu with y, z fixed)\n",
               kStarfishTetgenSwitches, scene.mesh.num_vertices(), scene.mesh.num_elements(), scene.mesh.num_dofs(),
               scene.dirichlet.dofs.size() / 2);
  std::fprintf(log,
               "# muscles (elements): -z %zu, +z %zu, -y %zu, +y %zu; %d wetted triangles; %s, %d steps per frame\n",
               scene.muscles[0].elements.size(), scene.muscles[1].elements.size(), scene.muscles[2].elements.size(),
               scene.muscles[3].elements.size(), static_cast<int>(scene.hydrodynamics->triangles.cols()),
               ToString(method), substeps_);
  std::fprintf(log, "# calibration: %s, rows %d..%d (t = %.3f..%.3f s, %d frames), marker weights 10/1/1/10\n",
               calibrate_path.c_str(), calibration.lines[fit_window.first], calibration.lines[fit_window.last],
               calibration.time[fit_window.first], calibration.time[fit_window.last], fit_window.num_frames());
  if (!fit_window.note.empty()) std::fprintf(log, "# note: %s\n", fit_window.note.c_str());

  // The fit.
  const MaterialParameters guess = scene.material;
  const StarfishActuation actuation_guess = ActuationGuess();
  std::fprintf(
      log,
      "# fit: %s on E in (1e4, 5e6) Pa, nu in (0.2, 0.45), tendon slack in (0, 15) mm, servo lag in (1, 500) "
      "ms, tendon length in (30, 130) mm%s%s%s (CoordinateManifold, log-logit but slack logit); "
      "cost = 1/2 weighted mean squared marker error / (2 mm)^2\n",
      fit_method_ == StarfishFitMethod::kLbfgs
          ? "Ceres L-BFGS on the scalar loss"
          : "Ceres Levenberg-Marquardt on per-frame marker residuals with forward-mode Jacobians",
      regions_ == StarfishRegions::kBodyArms ? ", E_arms like E" : "",
      release_in_model() ? ", servo release lag in (1, 500) ms" : "",
      (std::string(water_in_model()
                       ? ", water drag_tangential in (0.005, 5), drag_normal in (0.2, 20), thrust in (0.001, 10)"
                       : "") +
       (density_in_model() ? ", density in (50, 5000) kg/m^3" : "") +
       (damping_in_model() ? ", linear_damping in (0.01, 100) 1/s" : ""))
          .c_str());
  if (regions_ == StarfishRegions::kBodyArms)
    std::fprintf(log,
                 "# regions: body-arms: E of the %zu arm elements (centroid beyond |y|, |z| < 18 mm) fitted apart "
                 "from the body's %zu; nu and density shared\n",
                 scene.material_regions[0].elements.size(),
                 scene.mesh.num_elements() - scene.material_regions[0].elements.size());
  const int max_iterations = args.max_iterations >= 0 ? args.max_iterations
                             : density_in_model()     ? kDefaultIterationsWithDensity
                                                      : kDefaultIterations;
  StarfishStart first{guess, actuation_guess, WaterGuess()};
  if (release_in_model()) first.actuation.release_lag = first.actuation.lag;
  const std::vector<StarfishStart> starts = StarfishStarts(args.starts >= 0 ? args.starts : kDefaultStarts, first);
  std::vector<StarfishFit> start_fits;
  for (size_t k = 0; k < starts.size(); ++k) {
    const StarfishStart& s = starts[k];
    if (starts.size() > 1) {
      std::string more;
      if (release_in_model()) more += ", release lag = " + Num(*s.actuation.release_lag) + " s";
      if (water_in_model())
        more +=
            ", water " + Num(s.water.drag_tangential) + " / " + Num(s.water.drag_normal) + " / " + Num(s.water.thrust);
      std::fprintf(log,
                   "# start %zu of %zu: E = %.6g Pa, nu = %.6g, slack = %.3f mm, lag = %.4f s, length = %.2f mm%s\n",
                   k + 1, starts.size(), s.material.youngs_modulus, s.material.poissons_ratio, s.actuation.slack / kMm,
                   s.actuation.lag, s.actuation.length / kMm, more.c_str());
    }
    start_fits.push_back(Fit(calibration, fit_window, options, s.material, s.actuation, max_iterations, log, s.water));
    if (starts.size() > 1)
      std::fprintf(log, "# start %zu: cost %.6e -> %.6e (%s)\n", k + 1, start_fits.back().initial_cost,
                   start_fits.back().final_cost, start_fits.back().usable ? "usable" : "not usable");
  }
  const int best = BestStarfishFit(start_fits);
  const int chosen = best >= 0 ? best : 0;  // none usable: the first start's, reported as not usable
  if (starts.size() > 1)
    std::fprintf(log, "# starts: start %d has the lowest final cost on the calibration window\n", chosen + 1);
  const StarfishFit& fit = start_fits[chosen];
  const MaterialParameters& fitted = fit.material;
  const StarfishActuation& actuation = fit.actuation;
  const solvers::RolloutStatistics& stats = fit.statistics;
  std::fprintf(log,
               "# fit: %s after %d iterations; E = %.6g Pa, nu = %.6g, slack = %.3f mm, lag = %.4f s, "
               "length = %.2f mm; loss %.6e -> %.6e\n",
               fit.termination.c_str(), fit.iterations, fitted.youngs_modulus, fitted.poissons_ratio,
               actuation.slack / kMm, actuation.lag, actuation.length / kMm, fit.initial_cost, fit.final_cost);
  std::fprintf(log,
               "# fit: %ld rollouts (%.2f s forward), %ld gradients, %ld tangent passes (%.2f s derivatives), %ld "
               "failed\n",
               stats.rollouts, stats.forward_seconds, stats.gradients, stats.tangent_passes, stats.backward_seconds,
               stats.failures);
  if (fit.water_fitted)
    std::fprintf(log, "# fit: water drag_tangential = %.4g, drag_normal = %.4g, thrust = %.4g\n",
                 fit.water.drag_tangential, fit.water.drag_normal, fit.water.thrust);
  if (actuation.release_lag)
    std::fprintf(log, "# fit: asymmetric servo: release lag = %.4f s\n", *actuation.release_lag);
  if (fit.density_fitted) std::fprintf(log, "# fit: density = %.5g kg/m^3\n", fitted.density);
  if (fit.linear_damping) std::fprintf(log, "# fit: linear_damping = %.5g 1/s\n", *fit.linear_damping);
  const std::vector<std::string> fit_names = StarfishFitNames(actuation.release_lag.has_value(), fit.water_fitted,
                                                              fit.density_fitted, fit.linear_damping.has_value());
  const std::vector<double> fit_values = StarfishFitValues(fit);
  const int n = static_cast<int>(fit.standard_deviation.size());
  if (n > 0) {
    std::fprintf(log, "# uncertainty (ceres::Covariance, %d residuals, noise fitted): value, standard deviation\n",
                 fit.residuals);
    for (int i = 0; i < n; ++i)
      std::fprintf(log, "#   %-15s %12.6g +- %-12.4g%s\n", fit_names[i].c_str(), fit_values[i],
                   fit.standard_deviation[i], fit.at_bound[i] ? " (at a bound: the interval is not meaningful)" : "");
    std::fprintf(log, "# correlation:\n");
    for (int i = 0; i < n; ++i) {
      std::fprintf(log, "#   %-15s", fit_names[i].c_str());
      for (int j = 0; j < n; ++j) std::fprintf(log, " %6.3f", fit.correlation[n * i + j]);
      std::fprintf(log, "\n");
    }
  }
  if (!fit.region_materials.empty())
    std::fprintf(log, "# fit: arms E = %.6g Pa (body E = %.6g Pa, ratio %.3g)\n",
                 fit.region_materials[0].youngs_modulus, fitted.youngs_modulus,
                 fit.region_materials[0].youngs_modulus / fitted.youngs_modulus);
  if (stats.failures > 0) std::fprintf(log, "# last failure: %s\n", stats.last_error.c_str());

  // Predictions.
  nlohmann::json files = nlohmann::json::array();
  std::fprintf(log,
               "\n# predictions with the fitted material (first %g s of each file); baselines: no motion, each marker "
               "at its mean displacement\n%-40s %8s %8s %10s %12s %10s %12s %10s %12s %8s\n",
               seconds, "file", "seconds", "frames", "rmse_mm", "arm_rel_mm", "zero_mm", "zero_rel_mm", "mean_mm",
               "mean_rel_mm", "sim_s");
  for (size_t f = 0; f < predictions.size(); ++f) {
    const StarfishRecording& rec = predictions[f];
    const StarfishWindow& w = windows[f];
    if (!w.note.empty()) std::fprintf(log, "# note: %s\n", w.note.c_str());
    const Prediction p = Predict(rec, w, options, fit);
    if (!args.out_dir.empty()) {
      const std::string trace = WriteStarfishTrace(args.out_dir, rec, w, p.rollout, substeps_, p.simulated, p.captured);
      const std::string stem = std::filesystem::path(rec.path).stem().string();
      const std::string png = (std::filesystem::path(args.out_dir) / (stem + "_trace.png")).string();
      try {
        WriteStarfishTracePlot(trace, png,
                               stem + (rec.path == calibrate_path ? " (fitted on it)" : " (predicted)") +
                                   ": simulated and captured marker displacement, tendon");
      } catch (const std::runtime_error& e) {  // no gnuplot: the trace CSV stays
        std::fprintf(log, "# no plot: %s\n", e.what());
      }
      std::vector<double> times(rec.time.begin() + w.first, rec.time.begin() + w.last + 1);
      WriteStarfishVtk(args.out_dir, stem, scene.mesh, MarkerVertices(scene.mesh), p.rollout.states, substeps_, times,
                       p.captured, kVtkStride);
    }
    const StarfishErrors& e = p.errors;
    const StarfishBaselines& b = p.baselines;
    const double window_seconds = rec.time[w.last] - rec.time[w.first];
    std::fprintf(log, "%-40s %8.3f %8d %10.3f %12.3f %10.3f %12.3f %10.3f %12.3f %8.1f\n", rec.path.c_str(),
                 window_seconds, w.num_frames(), e.rmse / kMm, e.arm_relative_rmse / kMm, b.zero_motion.rmse / kMm,
                 b.zero_motion.arm_relative_rmse / kMm, b.mean_displacement.rmse / kMm,
                 b.mean_displacement.arm_relative_rmse / kMm, p.simulate_seconds);
    std::fflush(log);
    nlohmann::json j = {{"file", rec.path},
                        {"rmse_mm", e.rmse / kMm},
                        {"arm_relative_rmse_mm", e.arm_relative_rmse / kMm},
                        {"weighted_rms_mm", e.weighted_rms / kMm},
                        {"zero_motion_rmse_mm", b.zero_motion.rmse / kMm},
                        {"zero_motion_arm_relative_rmse_mm", b.zero_motion.arm_relative_rmse / kMm},
                        {"mean_displacement_rmse_mm", b.mean_displacement.rmse / kMm},
                        {"mean_displacement_arm_relative_rmse_mm", b.mean_displacement.arm_relative_rmse / kMm},
                        {"seconds", window_seconds},
                        {"frames", w.num_frames()},
                        {"used_for_calibration", rec.path == calibrate_path},
                        {"simulate_seconds", p.simulate_seconds}};
    if (!w.note.empty()) j["note"] = w.note;
    files.push_back(j);
  }

  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_clock).count();
  std::fprintf(log, "# total %.1f s\n", total);
  if (args.json) {
    nlohmann::json start_costs = nlohmann::json::array();
    for (const StarfishFit& f : start_fits) start_costs.push_back(f.final_cost);
    nlohmann::json out = {{"problem", name()},
                          {"youngs_modulus", fitted.youngs_modulus},
                          {"poissons_ratio", fitted.poissons_ratio},
                          {"density", fitted.density},
                          {"tendon_slack_mm", actuation.slack / kMm},
                          {"tendon_lag_s", actuation.lag},
                          {"tendon_length_mm", actuation.length / kMm},
                          {"tendon_release_lag_s",
                           actuation.release_lag ? nlohmann::json(*actuation.release_lag) : nlohmann::json(nullptr)},
                          {"truth", nlohmann::json::object()},
                          {"initial_guess",
                           {{"youngs_modulus", starts[chosen].material.youngs_modulus},
                            {"poissons_ratio", starts[chosen].material.poissons_ratio},
                            {"tendon_slack_mm", starts[chosen].actuation.slack / kMm},
                            {"tendon_lag_s", starts[chosen].actuation.lag},
                            {"tendon_length_mm", starts[chosen].actuation.length / kMm}}},
                          {"method", ToString(method)},
                          {"initial_cost", fit.initial_cost},
                          {"final_cost", fit.final_cost},
                          {"iterations", fit.iterations},
                          {"starts", starts.size()},
                          {"chosen_start", chosen},
                          {"start_final_costs", start_costs},
                          {"evaluations", stats.rollouts},
                          {"gradient_evaluations", stats.gradients},
                          {"failed_evaluations", stats.failures},
                          {"forward_seconds", stats.forward_seconds},
                          {"backward_seconds", stats.backward_seconds},
                          {"termination", fit.termination},
                          {"usable", fit.usable},
                          {"mesh",
                           {{"nodes", scene.mesh.num_vertices()},
                            {"tets", scene.mesh.num_elements()},
                            {"tetgen_switches", kStarfishTetgenSwitches}}},
                          {"steps_per_frame", substeps_},
                          {"calibration",
                           {{"file", calibrate_path},
                            {"start_s", calibration.time[fit_window.first]},
                            {"seconds", calibration.time[fit_window.last] - calibration.time[fit_window.first]},
                            {"frames", fit_window.num_frames()},
                            {"marker_weights", kMarkerWeights}}},
                          {"files", files},
                          {"total_seconds", total}};
    out["regions"] = ToString(regions_);
    out["water"] = {{"fitted", fit.water_fitted},
                    {"drag_tangential", fit.water.drag_tangential},
                    {"drag_normal", fit.water.drag_normal},
                    {"thrust", fit.water.thrust}};
    out["fit"] = ToString(fit_method_);
    out["density_fitted"] = fit.density_fitted;
    out["linear_damping"] = fit.linear_damping ? nlohmann::json(*fit.linear_damping) : nlohmann::json(nullptr);
    if (!fit.standard_deviation.empty()) {
      nlohmann::json sd, bound;
      for (int i = 0; i < n; ++i) {
        sd[fit_names[i]] = fit.standard_deviation[i];
        bound[fit_names[i]] = static_cast<bool>(fit.at_bound[i]);
      }
      out["standard_deviation"] = sd;
      out["at_bound"] = bound;
      out["correlation"] = fit.correlation;
    }
    if (!fit.region_materials.empty()) out["arms_youngs_modulus"] = fit.region_materials[0].youngs_modulus;
    std::printf("%s\n", out.dump(2).c_str());
  }
  return fit.usable ? 0 : 5;
}

}  // namespace diffpd::problems
