// calibrate-starfish: fit the material and tendon actuation of a soft
// underwater starfish robot to real captured motion and predict recordings
// not used for the fit (after Du et al., "Underwater soft robot modeling and
// control with differentiable simulation", RA-L 2021; data and fact sheet in
// the shared data/starfish/FACTS.md, read in place).
//
// The parts, one file each: the recordings and their windows
// (starfish_recording.h), the scene (starfish_scene.h: mesh, markers,
// muscles, water), the tendon actuation model (starfish_actuation.h), the fit
// and its bounds (starfish_fit.h), the errors and baselines
// (starfish_metrics.h) and the trace files (starfish_trace.h). This problem
// joins them: the simulation of a window (implicit Euler with 2 steps per
// camera frame, h = 8.3 ms, the original used 5; pd-lbfgs), the fit on a
// window of one recording and the prediction of others.
#pragma once

#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibration/starfish_actuation.h"
#include "calibration/starfish_fit.h"
#include "calibration/starfish_metrics.h"
#include "calibration/starfish_recording.h"
#include "calibration/starfish_scene.h"
#include "diffpd/captured_motion.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "problem.h"

namespace diffpd::problems {

class StarfishCalibration : public Problem {
 public:
  // Marker weights of the fit, M1..M4 (weights of the squared errors).
  static constexpr std::array<double, 4> kMarkerWeights = kStarfishMarkerWeights;
  static constexpr double kFrameRate = kStarfishFrameRate;  // Hz, the camera
  static constexpr double kTendonRest = 0.065;              // m: the fact sheet's a = 1 - contraction / 65 mm

  std::string name() const override { return "calibrate-starfish"; }
  std::string description() const override;
  // MakeStarfishScene(regions()): the starting material E = 5e5 Pa, nu =
  // 0.4, rho = 400 (with kBodyArms also as the arms' material region).
  Scene MakeScene() const override;
  int default_steps() const override { return static_cast<int>(substeps_ * kFrameRate); }  // 1 s
  double default_time_step() const override { return 1.0 / (kFrameRate * substeps_); }

  // Simulation steps per camera frame (default 2, h = 8.3 ms).
  int substeps() const { return substeps_; }
  void set_substeps(int substeps);
  // Material regions of the scene and the fit (default kNone).
  StarfishRegions regions() const { return regions_; }
  void set_regions(StarfishRegions regions) { regions_ = regions; }

  // Whether the lm fit fits the water's drag and thrust coefficients too
  // (default true; the lbfgs fit keeps the scene's).
  bool fit_water() const { return fit_water_; }
  void set_fit_water(bool fit) { fit_water_ = fit; }
  // Whether the lm fit models an asymmetric servo and fits its release lag
  // (StarfishActuation::release_lag; default true; the lbfgs fit keeps a
  // symmetric servo).
  bool fit_release_lag() const { return fit_release_lag_; }
  void set_fit_release_lag(bool fit) { fit_release_lag_ = fit; }
  // Whether Fit fits the release lag (fit_release_lag() and the lm fit).
  bool release_in_model() const { return fit_release_lag_ && fit_method_ == StarfishFitMethod::kLevenbergMarquardt; }
  // Whether the water joins a model (fit_water() and the lm fit).
  bool water_in_model() const { return fit_water_ && fit_method_ == StarfishFitMethod::kLevenbergMarquardt; }

  // Whether the lm fit fits the body's density (the mass it moves with the
  // water it carries; default true, from the scene's 400 kg/m^3, chosen by
  // cross-validation between the recordings: docs/benchmarks.md) and a
  // linear damping (Scene::linear_damping, from DampingGuess(); default
  // false: none).
  bool fit_density() const { return fit_density_; }
  void set_fit_density(bool fit) { fit_density_ = fit; }
  bool fit_damping() const { return fit_damping_; }
  void set_fit_damping(bool fit) { fit_damping_ = fit; }
  // Whether the density and the damping join a model (chosen and the lm fit).
  bool density_in_model() const { return fit_density_ && fit_method_ == StarfishFitMethod::kLevenbergMarquardt; }
  bool damping_in_model() const { return fit_damping_ && fit_method_ == StarfishFitMethod::kLevenbergMarquardt; }

  // How Fit minimises (default kLevenbergMarquardt).
  StarfishFitMethod fit_method() const { return fit_method_; }
  void set_fit_method(StarfishFitMethod method) { fit_method_ = method; }

  // Vertices of M1..M4 (StarfishMarkerVertices).
  static std::array<int, 4> MarkerVertices(const Mesh& mesh) { return StarfishMarkerVertices(mesh); }

  // The simulator inputs of a window: one activation per muscle per step
  // (zero-order hold of the frame's tendon value; num_frames - 1 frames of
  // substeps() steps), and the captured motion in simulation coordinates:
  // markers M1..M4 (ids 0..3) as vertices, sample times relative to the
  // window's first row, positions = marker position in `initial` + captured
  // displacement (x from image x, z from minus image y, y the initial y with
  // weight 0), weights sqrt(w_m / (sum w * (frames - 1))) / 2 mm on x and z,
  // so that 1/2 |r|^2 = 1/2 weighted mean squared error / (2 mm)^2.
  // WindowInputs throws what StarfishActivations throws, a negative
  // activation naming the recording's file and row ("<path>:<line>: tendon =
  // 80 mm gives activation -0.22 < 0 (...)"); WindowMotion what
  // CapturedMotion::Validate throws, prefixed by "<path>:<line>: ".
  std::vector<StepInput> WindowInputs(const StarfishRecording& recording, const StarfishWindow& window,
                                      const StarfishActuation& actuation) const;
  // The tendon contraction of every step of a window (m, zero-order hold).
  std::vector<double> WindowContractions(const StarfishRecording& recording, const StarfishWindow& window) const;
  CapturedMotion WindowMotion(const Mesh& mesh, const State& initial, const StarfishRecording& recording,
                              const StarfishWindow& window) const;
  // The window's initial state: rest if the activation of its first tendon
  // value (lag at steady state) is 1, else the quasi-static equilibrium
  // under that activation. A negative first activation names the row, as in
  // WindowInputs.
  State WindowInitialState(Simulator& sim, const StarfishRecording& recording, const StarfishWindow& window,
                           const StarfishActuation& actuation) const;
  // Errors of a simulated window (states at every step, rollout from
  // WindowInitialState) against the recording.
  StarfishErrors WindowErrors(const Mesh& mesh, const std::vector<State>& states, const StarfishRecording& recording,
                              const StarfishWindow& window) const;

  // Simulator settings of the fit and the predictions: relative tolerance
  // 1e-3 per step (abs 1e-6 N; tighter changes the marker RMSE by < 0.05 mm
  // at a multiple of the cost), backward relative tolerance 1e-8.
  SolverOptions Options(Method method, int threads) const;

  // The rollout function of a window at `material`, `actuation` and `water`:
  // blocks {E, nu} (Pa, 1; with kBodyArms {E, nu, E_arms, nu_arms}, the arms
  // region starting at `material` too), {slack, lag, length} (m, s, m; the
  // tendon actuation model, which writes every step's activations; with
  // `actuation`'s release_lag set {slack, lag, length, release_lag}) and,
  // when water_in_model(), {drag_tangential, drag_normal, thrust} (a
  // StateForceBlock; otherwise the scene has `water`'s values), with
  // density_in_model() the material block {E, nu, density}, with
  // damping_in_model() a last block {linear_damping} (a StateForceBlock
  // starting at `linear_damping`, 1/s), and functional
  // 0: with fit_method() kLbfgs one row, the scalar loss 1/2 |r|^2 of the
  // marker residuals (LeastSquaresLoss; its gradient is one adjoint), with
  // kLevenbergMarquardt the marker residuals r themselves (MarkerResiduals,
  // 3 rows per marker and frame, y unweighted). The initial state is WindowInitialState at
  // `actuation` and is held fixed, so the gradient is exact when the window
  // starts with the tendon slack (a = 1, as in the default fit window from rest).
  // `motion` (not nullptr): the residuals of this motion instead of the
  // recording's (e.g. a synthetic recording with WindowMotion's markers,
  // sample times and weights).
  std::unique_ptr<solvers::RolloutFunction> MakeModel(const StarfishRecording& recording, const StarfishWindow& window,
                                                      const SolverOptions& options, const MaterialParameters& material,
                                                      const StarfishActuation& actuation,
                                                      const StarfishWater& water = StarfishWater(),
                                                      const CapturedMotion* motion = nullptr,
                                                      double linear_damping = DampingGuess()) const;

  // Fits E, nu, slack, lag and length (with kBodyArms also the arms' E;
  // when water_in_model() also the water's coefficients from `water_guess`)
  // on a window (when release_in_model() also the release lag, starting at
  // actuation_guess's release lag, or its lag when it has none; otherwise a
  // release lag of actuation_guess is ignored): FitStarfishLeastSquares or
  // FitStarfishLoss (fit_method()) on MakeModel's functional, starting from
  // `guess` (both regions) and `actuation_guess`, at most `max_iterations`
  // iterations; the iteration table goes to `log` (nullptr: silent). Throws
  // what MakeModel, StarfishFitStart and CheckStarfishWaterStart throw, and
  // InvalidInputError for kBodyArms with kLevenbergMarquardt ("the lm fit
  // has no tied arms' nu: fit body-arms regions with --fit lbfgs"). With
  // density_in_model() the density is fitted from guess.density, with
  // damping_in_model() the linear damping from DampingGuess().
  StarfishFit Fit(const StarfishRecording& recording, const StarfishWindow& window, const SolverOptions& options,
                  const MaterialParameters& guess, const StarfishActuation& actuation_guess, int max_iterations,
                  FILE* log, const StarfishWater& water_guess = WaterGuess()) const;

  // A window simulated with fitted parameters and compared with its
  // recording (Predict).
  struct Prediction {
    Rollout rollout;  // from WindowInitialState, substeps() steps per frame
    StarfishDisplacements simulated, captured;
    StarfishErrors errors;
    StarfishBaselines baselines;
    double simulate_seconds = 0;  // wall-clock time of the rollout
  };
  // Simulates `window` of `recording` with `fit`'s material (and region
  // materials), actuation and water. Throws what the simulator throws.
  Prediction Predict(const StarfishRecording& recording, const StarfishWindow& window, const SolverOptions& options,
                     const StarfishFit& fit) const;

  // The fit's starting water when fitted: the scene's drag, thrust 0.1 (the
  // fit keeps the thrust positive, StarfishWaterCoordinates).
  static StarfishWater WaterGuess() { return StarfishWater{0.05, 2.05, 0.1}; }
  // The fit's starting linear damping when fitted: 1 /s.
  static constexpr double DampingGuess() { return 1.0; }
  // The fit's starting actuation: slack 3 mm, lag 50 ms, length 65 mm.
  static StarfishActuation ActuationGuess() { return StarfishActuation{0.003, 0.05, kTendonRest}; }

  // `diffpd run calibrate-starfish [--calibrate FILE] [--predict FILE ...]
  // [--seconds S] [--json] [--threads T] [--max-iterations N] [--out DIR]
  // [--regions body-arms] [--fit lm|lbfgs] [--fit-start S] [--fit-seconds S]
  // [--water fitted|fixed] [--servo symmetric|asymmetric] [--starts N]
  // [--density fitted|fixed] [--damping fitted|fixed]`:
  // fits E, nu, tendon slack, lag and length (and with the lm fit, unless
  // --servo symmetric, the servo's release lag, and unless --water fixed,
  // the water's drag and thrust coefficients) on the calibration file's
  // window (default [1 s, 6 s]: the tendon first moves at 1.18 s in cyclic1;
  // 5 s take in the swimming, which a 2 s window does not pin down) by
  // Levenberg-Marquardt on the marker residuals (--fit lbfgs: L-BFGS on the
  // scalar loss; at most 20 iterations with the density fitted, else 10,
  // unless --max-iterations; 0: no fit,
  // predict at the starting values), prints the parameters' standard
  // deviations and correlations (lm), then simulates the first S seconds
  // (default 10) of every --predict file (any recording in the fact sheet's
  // format; default: the calibration file and, when no --calibrate is given,
  // cyclic2 too) with the fitted parameters and reports per file the errors
  // and the zero-motion and mean-displacement baselines. --starts N (1 to
  // 4, default 1) fits from the first N of StarfishStarts and keeps the fit
  // with the lowest cost on the calibration window; --density fixed keeps
  // the scene's density (fitted by default), --damping fitted adds a linear
  // damping to the lm fit.
  // --out DIR writes per predicted file DIR/<file stem>_trace.csv
  // (WriteStarfishTrace), its plot <stem>_trace.png (WriteStarfishTracePlot;
  // skipped with a note without gnuplot) and the simulated body with the
  // captured markers at 10 frames per second, <stem>_body.pvd and
  // <stem>_markers.pvd (WriteStarfishVtk).
  // Method: pd-lbfgs, or the first of --methods, or a --method other than
  // the command line's default pd. --threads as for every problem.
  // --regions body-arms fits the arms' E apart from the body's (kBodyArms,
  // with --fit lbfgs).
  int Run(const CommandArgs& args) const override;

 private:
  int substeps_ = 2;
  StarfishRegions regions_ = StarfishRegions::kNone;
  StarfishFitMethod fit_method_ = StarfishFitMethod::kLevenbergMarquardt;
  bool fit_water_ = true;
  bool fit_release_lag_ = true;
  bool fit_density_ = true;
  bool fit_damping_ = false;
};

}  // namespace diffpd::problems
