// Closed-loop swimming (DiffPD Sec. 7.4, "Starfish" and "Shark"): a soft
// body in water (quad hydrodynamics, quad_hydrodynamics.h) with muscle
// strips driven through a per-element delay line by a neural network that
// observes the state every step (strip_network_controller.h). The network's
// weights are trained through the differentiable simulation: every
// evaluation is one closed-loop rollout and its reverse pass
// (Simulator::Backward with the controller).
//
// Computing and reporting are apart: TrainSwimmer returns a TrainingResult;
// TrainingJson, PlotLearningCurve and WriteRolloutFrames report it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "control/adam.h"
#include "diffpd/simulator.h"
#include "diffpd/strip_network_controller.h"
#include "problem.h"

namespace diffpd::problems {

// The original swimmers' loss, summed over the steps k = 1..K:
//   L = sum_k [ -d . vbar_k + side_weight |vbar_k - (d . vbar_k) d|^2 ],
// vbar_k the mean velocity of `nodes` after step k (m/s), d the unit swim
// direction; the reward is -L.
struct SwimLoss {
  std::vector<int> nodes;
  Vec3 direction = Vec3::UnitZ();
  double side_weight = 1.0;
  // L of a rollout; fills grad->dv (and sizes *grad) when not nullptr.
  double Evaluate(const Rollout& rollout, LossGradient* grad) const;
};

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

// The optimiser that trains the weights.
enum class ControlOptimizer { kAdam };
const char* ToString(ControlOptimizer optimizer);

struct TrainingSettings {
  int evaluations = 100;  // rollouts with a reverse pass (Adam: epochs); >= 1
  ControlOptimizer optimizer = ControlOptimizer::kAdam;
  AdamOptions adam;         // the original's settings by default
  std::uint64_t seed = 42;  // the network's initialisation
  FILE* log = nullptr;      // one line per evaluation (nullptr: silent); not owned
};

// One evaluation: the reward of the rollout at the parameters before the
// update, and what it cost.
struct TrainingEvaluation {
  int evaluation = 0;        // 0, 1, ...
  long simulated_steps = 0;  // steps simulated before this rollout (the learning curve's x)
  double reward = 0;         // -L
  double forward_seconds = 0;
  double backward_seconds = 0;  // 0 for the final evaluation (no gradient)
  double gradient_norm = 0;     // |dL/dtheta| (0 for the final evaluation)
};

struct TrainingResult {
  std::string optimizer;
  Method method = Method::kPdLbfgs;
  int dofs = 0, steps = 0, parameters = 0;
  double time_step = 0;
  // evaluations + 1 entries: the last is the final controller, evaluated
  // without a gradient.
  std::vector<TrainingEvaluation> history;
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

// Trains the swimmer's controller from MakeSwimmerController(swimmer, seed)
// with `options` (method, tolerances, threads; the time step is the
// swimmer's). Throws InvalidInputError for bad settings, SolverError when a
// rollout fails.
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

// A learning curve of the original code (learning_curves/*.csv of the
// shared paper data: x = simulated steps, y = reward).
struct ReferenceCurve {
  std::string label;
  std::vector<std::pair<double, double>> points;
};
// Reads "x,y" rows. Throws InvalidInputError naming the file and line.
ReferenceCurve ReadReferenceCurve(const std::string& path, const std::string& label);

// Writes <dir>/learning_curve.dat and, with gnuplot, <dir>/learning_curve.png:
// reward against simulated steps (log x) of the run and of the reference
// curves. Returns the written paths (the PNG only if gnuplot succeeded).
std::vector<std::string> PlotLearningCurve(const std::string& dir, const std::string& title,
                                           const TrainingResult& result, const std::vector<ReferenceCurve>& references);
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
  // [--evaluations E] [--seed S] [--no-compare] [--out DIR] [--json]`:
  // trains with Adam (the original's settings) for E evaluations (default
  // 100; small: small_evaluations()), then (unless --no-compare) times a
  // few evaluations with newton-cholesky and the method; prints a line per
  // evaluation and a summary, writes the learning curve (.dat, .png), the
  // final controller's rollout (.pvd) and summary.json into DIR (default
  // out/<problem>). Exit code 0 when the final reward is above the initial
  // one, 5 otherwise.
  int Run(const CommandArgs& args) const override;
};

}  // namespace diffpd::problems
