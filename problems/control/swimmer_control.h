// Closed-loop swimming (DiffPD Sec. 7.4, "Starfish" and "Shark"): a soft
// body in water (quad hydrodynamics, quad_hydrodynamics.h) with muscle
// strips driven through a per-element delay line by a neural network that
// observes the state every step (strip_network_controller.h). The network's
// weights are trained through the differentiable simulation: every
// evaluation is one closed-loop rollout and its reverse pass, made by the
// rollout core (solvers/core: a RolloutFunction with a ControllerBlock and
// the swim loss), and the optimisers (swimmer_optimizers.h) are Adam, Ceres'
// L-BFGS and Ipopt through their adapters.
//
// Computing and reporting are apart: TrainSwimmer returns a TrainingResult;
// TrainingJson, PlotLearningCurves and WriteRolloutFrames report it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "control/adam.h"
#include "control/evaluation_budget.h"
#include "control/reference_curve.h"
#include "control/swim_loss.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "diffpd/strip_network_controller.h"
#include "problem.h"

namespace diffpd::problems {

// A swimmer: its scene (muscles of the strips, quad hydrodynamics), the
// strips' muscles (root to tip) and drives, what the network observes and
// its hidden widths, the loss and the rollout length.
struct Swimmer {
  Scene scene;
  std::vector<std::vector<int>> strips;
  std::vector<StripDrive> drives;
  NodeObservation observation;
  std::vector<int> hidden_widths = {64, 64};
  int channels = 1;
  SwimLoss loss;
  int steps = 200;
  double time_step = 1.0 / 30;  // s
};

// The swimmer's controller: widths (observation, hidden..., channels), tanh
// everywhere, orthogonal weights with gain 5/3 and zero biases from `seed`
// (the original's initialisation; its torch draws are not reproduced).
StripNetworkController MakeSwimmerController(const Swimmer& swimmer, std::uint64_t seed);

// The optimiser that trains the weights (swimmer_optimizers.h): Adam with
// the original's settings, Ceres' L-BFGS (needs the Ceres adapter), Ipopt
// with a limited-memory Hessian (needs the Ipopt adapter).
enum class ControlOptimizer { kAdam, kLbfgs, kIpopt };
// "adam", "lbfgs", "ipopt".
const char* ToString(ControlOptimizer optimizer);
// Throws InvalidInputError: "optimizer 'sgd' is unknown: valid optimizers are adam, lbfgs, ipopt".
ControlOptimizer ParseControlOptimizer(const std::string& name);
// Whether this build has the optimiser's adapter.
bool ControlOptimizerAvailable(ControlOptimizer optimizer);

struct TrainingSettings {
  int evaluations = 100;  // rollouts with a reverse pass (Adam: epochs); >= 1
  ControlOptimizer optimizer = ControlOptimizer::kAdam;
  AdamOptions adam;         // the original's settings by default
  std::uint64_t seed = 42;  // the network's initialisation
  FILE* log = nullptr;      // one line per evaluation (nullptr: silent); not owned
};

struct TrainingResult {
  std::string optimizer;
  // How the optimiser ended (Ceres' brief report, Ipopt's status; Adam: empty).
  std::string optimizer_report;
  Method method = Method::kPdLbfgs;
  int dofs = 0, steps = 0, parameters = 0;
  double time_step = 0;
  // One entry per evaluation the optimiser made (at most the budget; a
  // failed rollout has none) and a last one for the final controller
  // (re-evaluated without a gradient where the optimiser had not evaluated
  // it; its simulated_steps are those of the whole training).
  std::vector<TrainingEvaluation> history;
  int failed_evaluations = 0;
  VectorXd initial_parameters, final_parameters;
  Rollout final_rollout;     // the final controller's
  double total_seconds = 0;  // wall time of the whole training

  double initial_reward() const { return history.front().reward; }
  double final_reward() const { return history.back().reward; }
  double best_reward() const;
  // Mean forward and backward seconds per evaluation (the evaluations with a gradient).
  double mean_forward_seconds() const;
  double mean_backward_seconds() const;
};

// The swimmer's training as a rollout function (solvers/core): one
// ControllerBlock with MakeSwimmerController(swimmer, seed) and the swim loss
// as functional 0; `options`' time step is replaced by the swimmer's.
std::unique_ptr<solvers::RolloutFunction> MakeSwimmerFunction(const Swimmer& swimmer, const SolverOptions& options,
                                                              std::uint64_t seed);

// Trains the swimmer's controller from MakeSwimmerController(swimmer, seed)
// with `options` (method, tolerances, threads; the time step is the
// swimmer's) and settings.optimizer within settings.evaluations rollouts.
// Throws InvalidInputError for bad settings or an optimiser this build
// lacks, SolverError when an Adam rollout or the final one fails.
TrainingResult TrainSwimmer(const Swimmer& swimmer, const SolverOptions& options, const TrainingSettings& settings);

// Seconds per evaluation (closed-loop rollout + reverse pass) with each
// method, at the initial controller of `seed`: the median of `repeats`
// evaluations, the methods interleaved in each round so that they see the
// same machine load.
struct EvaluationTiming {
  Method method = Method::kPdLbfgs;
  double forward_seconds = 0;   // median
  double backward_seconds = 0;  // median
  double reward = 0;            // of the rollout (the methods agree to their tolerance)
  int repeats = 0;
};
std::vector<EvaluationTiming> TimeEvaluations(const Swimmer& swimmer, const SolverOptions& options,
                                              const std::vector<Method>& methods, int repeats, std::uint64_t seed);

// Writes the runs' curves (<dir>/learning_curve.dat for one run,
// learning_curve_<optimizer>.dat for several), the reference curves
// (reference_<i>.dat) and, with gnuplot, <dir>/learning_curve.png: reward
// against simulated steps (log x), all on the same axes. Returns the written
// paths (the PNG only if gnuplot succeeded).
std::vector<std::string> PlotLearningCurves(const std::string& dir, const std::string& title,
                                            const std::vector<const TrainingResult*>& results,
                                            const std::vector<ReferenceCurve>& references);
// Writes the final rollout as <dir>/<name>.pvd and its frames (with the
// velocity as point data); returns the .pvd path.
std::string WriteRolloutFrames(const std::string& dir, const std::string& name, const Mesh& mesh,
                               const Rollout& rollout);

nlohmann::json TrainingJson(const TrainingResult& result);
nlohmann::json TimingJson(const std::vector<EvaluationTiming>& timings);

// A swimming problem for `diffpd run`.
class SwimmerControl : public Problem {
 public:
  // The full instance (the paper's) or the small one (CI: under a minute).
  virtual Swimmer MakeSwimmer(bool small) const = 0;
  // Step solver settings (method and threads are the command line's): the
  // original's tolerances, rel 1e-3 and abs 1e-4 N per step, adjoint solves
  // to a relative residual of 1e-6.
  virtual SolverOptions BaseOptions(bool small) const;
  // Evaluations of the small instance's training.
  virtual int small_evaluations() const { return 10; }
  // The stem of the original's learning curves ("starfish": starfish_diffpd.csv, starfish_ppo.csv).
  virtual std::string reference_stem() const = 0;

  Scene MakeScene() const override { return MakeSwimmer(false).scene; }
  int default_steps() const override { return MakeSwimmer(false).steps; }
  double default_time_step() const override { return MakeSwimmer(false).time_step; }

  // `diffpd run <problem> [--small] [--method M] [--threads T]
  // [--evaluations E] [--seed S] [--optimizer O] [--no-compare] [--out DIR]
  // [--json]`: trains with O (adam, the original's settings, by default;
  // lbfgs; ipopt; all: each available one in turn, from the same seed) for E
  // evaluations (default
  // 100; small: small_evaluations()), then (unless --no-compare) times a
  // few evaluations with newton-cholesky and the method; prints a line per
  // evaluation and a summary, writes the learning curve (.dat, .png), the
  // final controller's rollout (.pvd) and summary.json into DIR (default
  // out/<problem>; with several optimisers, frames_<optimizer>/ and
  // summary.json's "runs"). Exit code 0 when every final reward is above
  // its initial one, 5 otherwise.
  int Run(const CommandArgs& args) const override;
};

}  // namespace diffpd::problems
