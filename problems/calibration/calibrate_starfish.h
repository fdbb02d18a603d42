// calibrate-starfish: fit the material of a soft underwater starfish robot to
// real captured motion and predict recordings not used for the fit (after Du
// et al., "Underwater soft robot modeling and control with differentiable
// simulation", RA-L 2021; data and fact sheet in the shared
// data/starfish/FACTS.md, read in place).
//
// The body: the shared starfish_half_simplified.obj (metres) tetrahedralised
// by TetGen with switches "pq2Y" (surface kept, radius-edge ratio <= 2):
// 780 nodes, 2163 linear tets. pd-corotated + pd-volume, density 400 kg/m^3,
// no gravity, no contact. Boundary: every node with |y| < 18 mm and
// |z| < 18 mm has y and z fixed (x free). Four muscles (one per arm, k = 2e6
// Pa): the elements with a face on the flat face x = 0 (>= 3 nodes within
// 1 mm of it; the fact sheet's "a node within 1 mm" takes in, on this coarse
// mesh, tets spanning the thin arm tips' whole thickness, which shorten the
// arms instead of curling them), centroid in the arm's central strip
// (|y| <= 7.5 mm for z-arms, |z| <= 7.5 mm for y-arms) and beyond the
// central square; fibres along the arm. All four are driven by the same
// activation (one servo pulls all legs), StarfishActuation below: the
// recorded tendon contraction, held per camera frame, through a fitted servo
// lag and tendon slack, a = 1 - (c - slack) / 65 mm. Water: drag and
// thrust on every boundary triangle (state_forces.h, fluid density 1000
// kg/m^3, Cd from 0.05 along the face to 2.05 normal to it, no separate
// thrust term: the normal pressure is the normal drag). Implicit Euler with 2
// steps per camera frame (h = 8.3 ms; the original used 5), pd-lbfgs.
// Prints per file the unweighted marker RMSE and the arm-relative RMSE (mm).
// Markers M1..M4 are the vertices chosen as in FACTS.md; their simulated x
// and z displacements are compared with the recording's x and minus y
// displacements (mm), relative to the window's first frame.
#pragma once

#include <array>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/captured_motion.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "problem.h"

namespace diffpd::problems {

// One recording of the starfish (the CSV of FACTS.md): a header row, then 10
// numbers per row: time (ms), tendon contraction (mm, NaN allowed), M1 x, M1 y,
// ..., M4 x, M4 y (mm, image plane). Stored here in SI units.
struct StarfishRecording {
  std::string path;
  std::vector<double> time;    // s, strictly increasing
  std::vector<double> tendon;  // m; NaN where the file has NaN
  // Per row: image x and image y (m) of M1..M4: {x1, y1, x2, y2, ..., x4, y4}.
  std::vector<std::array<double, 8>> markers;
  std::vector<int> lines;  // file line of each row (the header is line 1)

  int num_rows() const { return static_cast<int>(time.size()); }
};

// Reads a starfish recording. Throws InvalidInputError naming the file and
// line:
//   "cannot open '<path>'", "cannot open '<path>': it is a directory, not a file",
//   "<path>: empty file (expected a header row and data rows)",
//   "<path>:1: expected a header row of 10 column labels, got 3 fields",
//   "<path>:5: expected 10 fields (time ms, tendon mm, M1 x, M1 y, ..., M4 x, M4 y), got 9",
//   "<path>:5: M2 y is not a number: 'abc'",
//   "<path>:5: M2 y = nan is invalid: marker coordinates must be finite and within +-1e+09 (mm)"
//   (kMaxMarkerCoordinate, captured_motion.h),
//   "<path>:5: time = inf is invalid: must be finite (ms)",
//   "<path>:5: tendon = inf is invalid: must be finite or NaN (mm)",
//   "<path>:5: time 10 ms is not after the previous row's 16.6667 ms (line 4)",
//   "<path>: no data rows".
StarfishRecording ReadStarfishRecording(const std::string& path);

// The rows of a recording that a simulation covers: rows first..last, from
// the first row at or after `start` seconds to the last one within `seconds`
// after it, stopping before the first row with a NaN tendon value.
struct StarfishWindow {
  int first = 0;
  int last = 0;      // inclusive; last > first
  std::string note;  // why the window is shorter than asked ("" if it is not)
  int num_frames() const { return last - first + 1; }
};
// Throws InvalidInputError if `seconds` is not finite and > 0, if `start` is
// not finite and >= 0, if the recording has no row at or after `start`, or if
// fewer than two rows remain (e.g. the tendon is NaN from the start):
//   "<path>:<line>: tendon contraction is NaN at the window's first row (t = 33.8 s): nothing to simulate".
StarfishWindow MakeStarfishWindow(const StarfishRecording& recording, double start, double seconds);

// Marker displacement errors of a simulated window, metres.
struct StarfishErrors {
  double rmse = 0;               // sqrt(mean over frames 1.. and markers of |d_sim - d_cap|^2), (x, z)
  double arm_relative_rmse = 0;  // the same after subtracting each frame's mean x displacement of the markers
  double weighted_rms = 0;       // sqrt(sum w_m |d_sim - d_cap|^2 / sum w_m) averaged over frames
  int frames = 0;                // frames compared (frame 0 excluded: zero by construction)
};

// The map from the recorded tendon contraction c (servo command, m, held per
// camera frame) to the muscle activation of every simulation step, fitted
// with the material:
//   servo lag:  c_f(k) = (lag c_f(k-1) + h c(k)) / (lag + h)  (first-order
//               lag, implicit Euler per step h, starting at c_f = c of the
//               window's first frame),
//   slack:      a(k) = 1 - H(c_f(k) - slack) / length, H(x) = 0 for x <= 0,
//               x^2 / (2 mm) below 1 mm, x - 0.5 mm above (a slack tendon
//               pulls nothing; the quadratic onset keeps a smooth),
//   length:     the tendon length over which the contraction is spread (the
//               fact sheet's 65 mm).
// slack = 0, lag = 0, length = 65 mm is the fact sheet's a = 1 - c / 65 mm
// except below 1 mm.
struct StarfishActuation {
  double slack = 0;       // m, >= 0
  double lag = 0;         // s, >= 0
  double length = 0.065;  // m, > 0
};

// Activations a(k) of the steps of a contraction sequence (one value per
// step, m) at time step h (s), and if not nullptr, per step the derivatives
// {da/dslack (1/m), da/dlag (1/s), da/dlength (1/m)}. Throws
// InvalidInputError for h <= 0, a negative or non-finite slack or lag, or a
// length <= 0 ("tendon lag = -1 is invalid: must be finite and >= 0 (s)"),
// and for a negative activation ("tendon: activation -0.2 < 0 (the filtered
// contraction exceeds slack + length: slack 0 m, length 0.01 m) at step 7").
std::vector<double> StarfishActivations(const std::vector<double>& contraction, double h,
                                        const StarfishActuation& actuation,
                                        std::vector<std::array<double, 3>>* derivatives);

// Material regions of the starfish fit.
enum class StarfishRegions {
  kNone,      // one material
  kBodyArms,  // material region 0: the four arms (element centroid beyond
              // the central square |y|, |z| < 18 mm), with its own E; the
              // central body keeps the base material; nu and density shared
};
// "none", "body-arms".
const char* ToString(StarfishRegions regions);
// Throws InvalidInputError for other names:
//   "--regions = 'legs' is invalid: calibrate-starfish knows 'body-arms'".
StarfishRegions ParseStarfishRegions(const std::string& name);

// The outcome of a fit (StarfishCalibration::Fit).
struct StarfishFit {
  MaterialParameters material;  // fitted (the body's with kBodyArms)
  // kBodyArms: the arms' fitted material (E fitted; nu = material's,
  // density = material's); empty otherwise.
  std::vector<MaterialParameters> region_materials;
  StarfishActuation actuation;  // fitted
  double initial_cost = 0;      // loss 1/2 |r|^2 (see WindowMotion) at the start
  double final_cost = 0;
  int iterations = 0;                     // Ceres L-BFGS iterations
  bool usable = false;                    // Ceres' solution is usable
  std::string termination;                // Ceres' message
  solvers::RolloutStatistics statistics;  // rollouts, gradients, timings
};

class StarfishCalibration : public Problem {
 public:
  // Marker weights of the fit, M1..M4 (weights of the squared errors).
  static constexpr std::array<double, 4> kMarkerWeights = {10, 1, 1, 10};
  static constexpr double kFrameRate = 60;      // Hz, the camera
  static constexpr double kTendonRest = 0.065;  // m: the fact sheet's a = 1 - contraction / 65 mm

  std::string name() const override { return "calibrate-starfish"; }
  std::string description() const override;
  // The scene at the starting material E = 5e5 Pa, nu = 0.4, rho = 400
  // (with kBodyArms also as the arms' material region).
  Scene MakeScene() const override;
  int default_steps() const override { return static_cast<int>(substeps_ * kFrameRate); }  // 1 s
  double default_time_step() const override { return 1.0 / (kFrameRate * substeps_); }

  // Simulation steps per camera frame (default 2, h = 8.3 ms).
  int substeps() const { return substeps_; }
  void set_substeps(int substeps);
  // Material regions of the scene and the fit (default kNone).
  StarfishRegions regions() const { return regions_; }
  void set_regions(StarfishRegions regions) { regions_ = regions; }

  // The mesh of the file comment (tetgen must be on PATH).
  static Mesh StarfishMesh();
  // Vertices of M1..M4 (FACTS.md's rule) on `mesh`, in metres.
  static std::array<int, 4> MarkerVertices(const Mesh& mesh);

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

  // The rollout function of a window at `material` and `actuation`: blocks
  // {E, nu} (Pa, 1; with kBodyArms {E, nu, E_arms, nu_arms}, the arms region
  // starting at `material` too) and {slack, lag, length} (m, s, m; the tendon
  // actuation model, which writes every step's activations), and one row, the
  // scalar loss 1/2 |r|^2 of the marker residuals (LeastSquaresLoss; its
  // gradient is one adjoint). The initial state is WindowInitialState at
  // `actuation` and is held fixed, so the gradient is exact when the window
  // starts with the tendon slack (a = 1, as in the default fit window from rest).
  std::unique_ptr<solvers::RolloutFunction> MakeModel(const StarfishRecording& recording, const StarfishWindow& window,
                                                      const SolverOptions& options, const MaterialParameters& material,
                                                      const StarfishActuation& actuation) const;

  // Fits E, nu, slack, lag and length on a window with Ceres' L-BFGS
  // (GradientProblem) on the bounded coordinates below (u = 2 material then
  // 3 actuation coordinates; with kBodyArms a sixth, the arms' E mapped like
  // E, and the arms' nu tied to the body's), starting from `guess` (both
  // regions) and `actuation_guess`,
  // at most `max_iterations` iterations; the iteration table goes to `log`
  // (nullptr: silent). Throws what MakeModel throws; a failed rollout makes Ceres
  // shorten its step (the failure is counted in statistics).
  StarfishFit Fit(const StarfishRecording& recording, const StarfishWindow& window, const SolverOptions& options,
                  const MaterialParameters& guess, const StarfishActuation& actuation_guess, int max_iterations,
                  FILE* log) const;

  // Bounds of the fit: E in [1e4, 5e6] Pa, nu in [0.2, 0.45]. The optimiser's
  // coordinates u (2 numbers) map to log E = lo + (hi - lo) s(u_0), log nu
  // likewise, s(u) = 1 / (1 + exp(-u)).
  static MaterialParameters FromCoordinates(const double* u, double density);
  // Inverse map; throws InvalidInputError for E or nu outside the open
  // intervals, e.g. "youngs_modulus = 6e+06 is outside the fit's interval (1e4, 5e6) Pa".
  static void ToCoordinates(const MaterialParameters& m, double* u);
  // Actuation coordinates (3 numbers): slack = 15 mm s(u_0); log lag in
  // [log 1 ms, log 0.5 s] and log length in [log 30 mm, log 130 mm] like
  // log E. The inverse throws InvalidInputError outside the open intervals
  // ("tendon slack = 0.02 is outside the fit's interval (0, 0.015) m").
  static StarfishActuation ActuationFromCoordinates(const double* u);
  static void ActuationToCoordinates(const StarfishActuation& a, double* u);
  // The fit's starting actuation: slack 3 mm, lag 50 ms, length 65 mm.
  static StarfishActuation ActuationGuess() { return StarfishActuation{0.003, 0.05, kTendonRest}; }

  // `diffpd run calibrate-starfish [--calibrate FILE] [--predict FILE ...]
  // [--seconds S] [--json] [--threads T] [--max-iterations N] [--out DIR]
  // [--regions body-arms]`:
  // fits E, nu, tendon slack, lag and length on the calibration file's window
  // [1 s, 3 s] (the tendon first moves at 1.18 s in cyclic1) with Ceres'
  // L-BFGS on the scalar loss (at most 10 iterations unless
  // --max-iterations; 0: no fit, predict at the starting values), then
  // simulates the first S seconds (default 10) of every --predict file
  // (default: the calibration file and, when no --calibrate is given,
  // cyclic2 too) with the fitted parameters and reports the errors.
  // --out DIR writes DIR/<file stem>_trace.csv per predicted file: time,
  // tendon (mm), activation, simulated and captured x, z displacement of
  // M1..M4 (mm) per camera frame.
  // Method: pd-lbfgs, or the first of --methods, or a --method other than
  // the command line's default pd. --threads as for every problem.
  // --regions body-arms fits the arms' E apart from the body's (kBodyArms).
  int Run(const CommandArgs& args) const override;

 private:
  int substeps_ = 2;
  StarfishRegions regions_ = StarfishRegions::kNone;
};

}  // namespace diffpd::problems
