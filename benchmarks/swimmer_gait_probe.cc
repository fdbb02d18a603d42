// Benchmark (not a test): why the starfish's closed-loop training flattens.
// From one seed it trains, on the same budget of evaluations (rollout +
// reverse pass, 200 steps of the full starfish-control instance),
//
//   closed loop: the paper's 243-64-64-4 tanh network with Adam at the
//                original's settings (TrainSwimmer, what `diffpd run
//                starfish-control` does), and
//   open loop:   a free value per step and channel through the same drive
//                and delay line (StripOpenLoopController, the original's
//                open-loop form), from N(0, 1) draws of the seed (std::
//                normal_distribution), with Adam at a probe setting
//                (--open-lr, default 0.05; no clip, no decay, no schedule:
//                the values need steps of order 1, which the original's
//                1e-3 would take a thousand evaluations to make),
//
// and reports both learning curves and, for each final controller, how its
// four channel values move over the rollout: the steps at which every
// channel is saturated (|w_c| > 0.99, where tanh' < 0.02), the sign changes
// per channel (a stroke cycle changes sign twice) and the range of each
// channel after the first 20 steps. The open loop tells how much reward the
// simulated physics gives a cyclic gait at all; the closed loop's numbers
// show whether its network still moves its outputs. A third row is one
// rollout of the constant gait w = -1 on every channel (the bottom strips
// contract fully once and hold: one stroke, then coasting).
// --mass equal-nodes puts the original code's rho dx^3 on every node
// (Scene::mass_lumping) instead of the problem's lumped masses.
//
// Usage: swimmer_gait_probe [--evaluations 100] [--seed 42] [--open-lr 0.05]
//   [--mass lumped|equal-nodes] [--threads 1] [--json]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "control/starfish_control.h"
#include "control/swimmer_optimizers.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/core/controller_block.h"
#include "diffpd/strip_open_loop_controller.h"

namespace diffpd::problems {
namespace {

using nlohmann::json;

struct Settings {
  int evaluations = 100;
  int seed = 42;
  double open_learning_rate = 0.05;
  int threads = 1;
  MassLumping mass = MassLumping::kLumped;
  bool json = false;
};

// How a controller's channel values move over a rollout (w_k per step).
struct ChannelMotion {
  int steps = 0;
  int all_saturated_steps = 0;             // steps with every |w_c| > 0.99
  std::vector<int> sign_changes;           // per channel, over the whole rollout
  std::vector<double> late_min, late_max;  // per channel, steps >= 20
};

ChannelMotion Motion(const std::vector<VectorXd>& w) {
  ChannelMotion m;
  m.steps = static_cast<int>(w.size());
  const int channels = static_cast<int>(w.front().size());
  m.sign_changes.assign(channels, 0);
  m.late_min.assign(channels, INFINITY);
  m.late_max.assign(channels, -INFINITY);
  for (size_t k = 0; k < w.size(); ++k) {
    if (w[k].cwiseAbs().minCoeff() > 0.99) ++m.all_saturated_steps;
    for (int c = 0; c < channels; ++c) {
      if (k > 0 && (w[k](c) > 0) != (w[k - 1](c) > 0)) ++m.sign_changes[c];
      if (k >= 20) {
        m.late_min[c] = std::min(m.late_min[c], w[k](c));
        m.late_max[c] = std::max(m.late_max[c], w[k](c));
      }
    }
  }
  return m;
}

struct Run {
  std::string name;
  std::vector<TrainingEvaluation> history;
  ChannelMotion motion;
};

struct Probe {
  Settings settings;
  int dofs = 0, steps = 0;
  Run closed, open, constant;
};

SolverOptions Options(const StarfishControl& problem, const Swimmer& swimmer, int threads) {
  SolverOptions o = problem.BaseOptions(false);
  o.num_threads = threads;
  o.time_step = swimmer.time_step;
  return o;
}

Run TrainClosedLoop(const StarfishControl& problem, const Swimmer& swimmer, const Settings& s) {
  TrainingSettings ts;
  ts.evaluations = s.evaluations;
  ts.seed = static_cast<std::uint64_t>(s.seed);
  ts.log = stderr;
  const TrainingResult result = TrainSwimmer(swimmer, Options(problem, swimmer, s.threads), ts);
  StripNetworkController controller = MakeSwimmerController(swimmer, ts.seed);
  controller.SetParameters(result.final_parameters);
  std::vector<VectorXd> w;
  for (int k = 0; k < result.final_rollout.num_steps(); ++k)
    w.push_back(controller.network().Evaluate(controller.Observe(result.final_rollout.states[k])));
  return Run{"closed loop (network, Adam lr 1e-3)", result.history, Motion(w)};
}

Run TrainOpenLoop(const StarfishControl& problem, const Swimmer& swimmer, const Settings& s) {
  const StripOpenLoopController prototype(
      swimmer.steps, swimmer.channels, MuscleDelayLine(swimmer.strips, static_cast<int>(swimmer.scene.muscles.size())),
      swimmer.drives);
  // Start from N(0, 1) draws (as the original's open-loop controller): at
  // w = 0 exactly no strip contracts and the gradient is 0 (the kink of max).
  std::mt19937_64 rng(static_cast<std::uint64_t>(s.seed));
  std::normal_distribution<double> normal;
  VectorXd start(prototype.num_parameters());
  for (Eigen::Index i = 0; i < start.size(); ++i) start(i) = normal(rng);
  StripOpenLoopController initial = prototype;
  initial.SetParameters(start);
  solvers::RolloutFunction function(swimmer.scene, Options(problem, swimmer, s.threads), swimmer.steps);
  function.AddBlock(std::make_unique<solvers::ControllerBlock>(initial));
  function.AddFunctional(std::make_unique<SwimLossFunction>(swimmer.loss));
  EvaluationBudget budget(&function, s.evaluations, swimmer.steps, stderr);
  AdamOptions adam;
  adam.learning_rate = s.open_learning_rate;
  adam.clip_norm = 0;
  adam.weight_decay = 0;
  adam.schedule_steps = 0;
  const VectorXd values = MinimizeWithAdam(&function, 0, adam, &budget);
  budget.Finish();
  StripOpenLoopController controller = prototype;
  controller.SetParameters(values);
  std::vector<VectorXd> w;
  for (int k = 0; k < swimmer.steps; ++k) w.push_back(controller.ChannelValues(k));
  char name[96];
  std::snprintf(name, sizeof(name), "open loop (per-step values, Adam lr %g)", s.open_learning_rate);
  return Run{name, budget.history(), Motion(w)};
}

// One rollout of w = -1 on every channel at every step.
Run ConstantCurl(const StarfishControl& problem, const Swimmer& swimmer, const Settings& s) {
  StripOpenLoopController controller(swimmer.steps, swimmer.channels,
                                     MuscleDelayLine(swimmer.strips, static_cast<int>(swimmer.scene.muscles.size())),
                                     swimmer.drives);
  controller.SetParameters(VectorXd::Constant(controller.num_parameters(), -20.0));  // tanh(-20) = -1 in doubles
  Simulator sim(swimmer.scene, Options(problem, swimmer, s.threads));
  const Rollout rollout = sim.Simulate(sim.RestState(), controller, swimmer.steps);
  TrainingEvaluation e;
  e.reward = -swimmer.loss.Evaluate(rollout, nullptr);
  std::vector<VectorXd> w;
  for (int k = 0; k < swimmer.steps; ++k) w.push_back(controller.ChannelValues(k));
  return Run{"constant w = -1 (no training)", {e}, Motion(w)};
}

Probe RunProbe(const Settings& settings) {
  const StarfishControl problem;
  Swimmer swimmer = problem.MakeSwimmer(false);
  swimmer.scene.mass_lumping = settings.mass;
  Probe p;
  p.settings = settings;
  p.dofs = swimmer.scene.mesh.num_dofs();
  p.steps = swimmer.steps;
  p.closed = TrainClosedLoop(problem, swimmer, settings);
  p.open = TrainOpenLoop(problem, swimmer, settings);
  p.constant = ConstantCurl(problem, swimmer, settings);
  return p;
}

double RewardAt(const std::vector<TrainingEvaluation>& h, int evaluation) {
  for (const TrainingEvaluation& e : h)
    if (e.evaluation == evaluation) return e.reward;
  return NAN;
}

double Best(const std::vector<TrainingEvaluation>& h) {
  double best = -INFINITY;
  for (const TrainingEvaluation& e : h) best = std::max(best, e.reward);
  return best;
}

void PrintTable(const Probe& p) {
  const int e = p.settings.evaluations;
  std::printf("starfish-control, %d DoFs, %d steps, %s masses, seed %d, %d evaluations each, %d thread(s)\n\n", p.dofs,
              p.steps, ToString(p.settings.mass), p.settings.seed, e, p.settings.threads);
  std::printf("| controller | reward at 0 | %d | %d | %d | best | steps all saturated | sign changes per channel |\n",
              e / 4, e / 2, e - 1);
  std::printf("|---|---|---|---|---|---|---|---|\n");
  std::printf("| %s | %.3f | | | | | %d of %d | |\n", p.constant.name.c_str(), p.constant.history[0].reward,
              p.constant.motion.all_saturated_steps, p.constant.motion.steps);
  for (const Run* r : {&p.closed, &p.open}) {
    std::string changes;
    for (size_t c = 0; c < r->motion.sign_changes.size(); ++c)
      changes += (c ? ", " : "") + std::to_string(r->motion.sign_changes[c]);
    std::printf("| %s | %.3f | %.3f | %.3f | %.3f | %.3f | %d of %d | %s |\n", r->name.c_str(), RewardAt(r->history, 0),
                RewardAt(r->history, e / 4), RewardAt(r->history, e / 2), RewardAt(r->history, e - 1), Best(r->history),
                r->motion.all_saturated_steps, r->motion.steps, changes.c_str());
  }
  std::printf("\nchannel ranges after step 20 (min .. max):\n");
  for (const Run* r : {&p.closed, &p.open}) {
    std::printf("  %s:", r->name.c_str());
    for (size_t c = 0; c < r->motion.late_min.size(); ++c)
      std::printf(" [%+.3f .. %+.3f]", r->motion.late_min[c], r->motion.late_max[c]);
    std::printf("\n");
  }
}

json RunJson(const Run& r) {
  json curve = json::array();
  for (const TrainingEvaluation& e : r.history)
    curve.push_back({{"evaluation", e.evaluation}, {"reward", e.reward}, {"gradient_norm", e.gradient_norm}});
  return {{"controller", r.name},
          {"best_reward", Best(r.history)},
          {"all_saturated_steps", r.motion.all_saturated_steps},
          {"steps", r.motion.steps},
          {"sign_changes", r.motion.sign_changes},
          {"late_min", r.motion.late_min},
          {"late_max", r.motion.late_max},
          {"learning_curve", curve}};
}

json ProbeJson(const Probe& p) {
  return {{"problem", "starfish-control"},
          {"dofs", p.dofs},
          {"steps", p.steps},
          {"seed", p.settings.seed},
          {"evaluations", p.settings.evaluations},
          {"open_learning_rate", p.settings.open_learning_rate},
          {"threads", p.settings.threads},
          {"mass", ToString(p.settings.mass)},
          {"constant_curl_reward", p.constant.history[0].reward},
          {"closed_loop", RunJson(p.closed)},
          {"open_loop", RunJson(p.open)}};
}

bool ParsePositive(const char* flag, const char* text, double* value) {
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || !std::isfinite(v) || v <= 0) {
    std::fprintf(stderr, "swimmer_gait_probe: %s = %s is invalid: must be a finite number > 0\n", flag, text);
    return false;
  }
  *value = v;
  return true;
}

}  // namespace
}  // namespace diffpd::problems

int main(int argc, char** argv) {
  using namespace diffpd::problems;
  Settings s;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    double v = 0;
    if (a == "--json") {
      s.json = true;
    } else if (i + 1 < argc && (a == "--evaluations" || a == "--seed" || a == "--threads")) {
      const char* text = argv[++i];
      if (a == "--seed") {
        char* end = nullptr;
        const long seed = std::strtol(text, &end, 10);
        if (end == text || *end != '\0' || seed < 0) {
          std::fprintf(stderr, "swimmer_gait_probe: --seed = %s is invalid: must be an integer >= 0\n", text);
          return 2;
        }
        s.seed = static_cast<int>(seed);
        continue;
      }
      if (!ParsePositive(a.c_str(), text, &v) || v != std::floor(v)) {
        if (v > 0)
          std::fprintf(stderr, "swimmer_gait_probe: %s = %s is invalid: must be an integer\n", a.c_str(), text);
        return 2;
      }
      (a == "--evaluations" ? s.evaluations : s.threads) = static_cast<int>(v);
    } else if (i + 1 < argc && a == "--mass") {
      const std::string m = argv[++i];
      if (m != "lumped" && m != "equal-nodes") {
        std::fprintf(stderr, "swimmer_gait_probe: --mass = %s is invalid: must be lumped or equal-nodes\n", m.c_str());
        return 2;
      }
      s.mass = m == "lumped" ? diffpd::MassLumping::kLumped : diffpd::MassLumping::kEqualNodes;
    } else if (i + 1 < argc && a == "--open-lr") {
      if (!ParsePositive("--open-lr", argv[++i], &s.open_learning_rate)) return 2;
    } else {
      std::fprintf(stderr,
                   "usage: swimmer_gait_probe [--evaluations 100] [--seed 42] [--open-lr 0.05] "
                   "[--mass lumped|equal-nodes] [--threads 1] [--json]\n");
      return 2;
    }
  }
  if (s.evaluations < 4) {
    std::fprintf(stderr, "swimmer_gait_probe: --evaluations = %d is invalid: must be >= 4\n", s.evaluations);
    return 2;
  }
  const Probe p = RunProbe(s);
  if (s.json)
    std::cout << ProbeJson(p).dump(1) << "\n";
  else
    PrintTable(p);
  return 0;
}
