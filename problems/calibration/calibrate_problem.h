// System identification problems (DiffPD Sec. 7.1): fit material parameters
// to captured marker motion with Ceres over the rollout core
// (diffpd/solvers/core/rollout_function.h), once per simulator method, and
// report the paper's table columns.
//
// The captured motion shipped in data/ is synthesised by the problem itself
// (Synthesize) from its true material with Newton-Cholesky at a tight
// tolerance, sampled at capture times that do not align with the steps, with
// Gaussian noise of documented standard deviation and fixed seed; the
// generator is `diffpd synth <problem> --dir data`, which writes
//   data/<data_file()>            with noise (the default input of the fit)
//   data/<stem>_clean.csv         without noise.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/captured_motion.h"
#include "diffpd/solvers/core/material_block.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "problem.h"

namespace diffpd::problems {

// The outcome of one fit.
struct CalibrationFit {
  Method method = Method::kPd;
  std::vector<solvers::MaterialField> fitted;  // of the base material
  std::vector<double> values;                  // fitted values, in `fitted` order
  std::vector<double> initial;                 // starting values
  double initial_cost = 0;                     // 1/2 sum of squared weighted residuals
  double final_cost = 0;
  double marker_rmse_m = 0;               // sqrt(mean over samples of |simulated - captured|^2), unweighted
  int iterations = 0;                     // Ceres iterations
  solvers::RolloutStatistics statistics;  // evaluations (rollouts), timings
  double total_seconds = 0;
  bool usable = false;      // Ceres' solution is usable and its final cost finite
  std::string termination;  // Ceres' message
  Rollout rollout;          // the fitted trajectory
};

class CalibrationProblem : public Problem {
 public:
  // File name of the shipped noisy captured motion in data/ (e.g.
  // "plant_motion.csv"); the clean one is <stem>_clean.csv.
  virtual std::string data_file() const = 0;
  // The material the shipped motion was made with; MakeScene() uses it.
  virtual MaterialParameters truth() const = 0;
  // Where every fit starts.
  virtual MaterialParameters initial_guess() const = 0;
  virtual std::vector<solvers::MaterialField> fitted() const {
    return {solvers::MaterialField::kYoungsModulus, solvers::MaterialField::kPoissonsRatio};
  }
  // Markers (ids 0..) and capture times (s) of the synthetic motion.
  virtual std::vector<Marker> Markers(const Mesh& mesh) const = 0;
  virtual std::vector<double> CaptureTimes() const = 0;
  // Standard deviation (m) of the noise on every coordinate of the shipped
  // data, and the seed of its generator (std::mt19937_64, Box-Muller).
  virtual double noise() const = 0;
  virtual std::uint64_t seed() const { return 2021; }
  // Methods fitted by default (the first is the main one).
  virtual std::vector<Method> default_methods() const { return {Method::kPdLbfgs, Method::kNewtonCholesky}; }
  // Simulator settings of a fit with `method`: time step default_time_step(),
  // rel_tolerance 1e-4 (abs 1e-9, at most 20000 iterations a step), adjoint
  // rel_tolerance 1e-8. Tighter forward tolerances give the same fit in more
  // time (docs/benchmarks.md, "What a tolerance costs the optimiser").
  virtual SolverOptions FitOptions(Method method) const;
  virtual int max_iterations() const { return 25; }

  // Problem interface: the rollout covers the capture times.
  int default_steps() const override;

  // The captured motion of the true material (with the documented noise
  // unless `clean`).
  CapturedMotion Synthesize(bool clean) const;
  // Writes <dir>/<data_file()> and <dir>/<stem>_clean.csv with a header that
  // documents the generator. Returns the two paths.
  std::vector<std::string> WriteSyntheticData(const std::string& dir) const;
  // The default input: data/<data_file()> of the source tree (or of the
  // directory in the environment variable DIFFPD_DATA when set).
  std::string DefaultDataPath() const;

  // The fit's model: a rollout function of MakeScene() at initial_guess()
  // with `solver`, covering the motion's capture times, one block (the
  // fitted() fields of the base material) and functional 0, the marker
  // residuals against `motion`. Throws InvalidInputError for a motion that
  // does not fit the problem's mesh.
  std::unique_ptr<solvers::RolloutFunction> MakeModel(const CapturedMotion& motion, const SolverOptions& solver) const;

  // One fit of fitted() with Ceres (Levenberg-Marquardt, log E and logit nu
  // steps, one residual block per frame sharing one rollout per point), its
  // iteration table on `log` (nullptr: silent). Throws InvalidInputError for
  // a motion that does not fit the problem's mesh.
  CalibrationFit Fit(const CapturedMotion& motion, Method method, int max_iterations, FILE* log) const;
  // The same fit with every evaluation at `solver` (method, tolerances,
  // threads; the time step is the problem's), e.g. to measure what a
  // tolerance costs the fit.
  CalibrationFit Fit(const CapturedMotion& motion, const SolverOptions& solver, int max_iterations, FILE* log) const;

  // `diffpd run <problem>`: fits the captured motion (--data FILE, default
  // DefaultDataPath()) with each of --methods (default default_methods();
  // --no-compare keeps the first), prints the iteration tables and a final
  // report (true vs recovered parameters with relative errors, marker RMSE,
  // the paper's columns: forward s, backward s, evaluations, final loss);
  // with --out DIR writes the fitted trajectory (VTK, first method), the
  // captured and simulated marker paths (markers.csv) and their plot
  // (markers.png, gnuplot) and calibration.json; with --json prints the
  // report as one JSON object on stdout (everything else on stderr).
  // Returns 0 if every fit is usable (Ceres says so and the final cost is
  // finite), 5 otherwise, with a line on stderr per unusable fit.
  int Run(const CommandArgs& args) const override;

  // The report of Run as JSON: fitted parameters of the first fit as
  // top-level numbers, "truth" with the same keys, "final_cost",
  // "evaluations", "forward_seconds", "backward_seconds", and "fits" with
  // one object per method.
  nlohmann::json Report(const std::vector<CalibrationFit>& fits, const std::string& data_path) const;

 private:
  // The true trajectory (newton-cholesky, relative tolerance 1e-11) and its
  // markers at the capture times.
  Rollout TruthRollout() const;
  CapturedMotion Sample(const Rollout& truth_rollout, bool clean) const;
};

}  // namespace diffpd::problems
