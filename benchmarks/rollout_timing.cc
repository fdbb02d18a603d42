// Benchmark (not a test): wall time of one registered problem's default
// rollout (Simulator::Simulate from the problem's initial state with its
// inputs) and, with --backward, of the reverse pass of a loss on the last
// positions, as the C++ API runs them. The reference for the Python
// package's overhead (benchmarks/python_overhead.py times the same calls
// through diffpd). One untimed rollout first (the PD factorisation), then
// `repeat` timed ones; prints one JSON object with every time and the median,
// and, per run, the time the steps themselves took as the simulator measures
// them (Rollout::forward_seconds, BackwardReport::seconds): the difference is
// what the call costs around its steps, a figure a loaded machine disturbs
// far less than the wall time.
// The step tolerance is `diffpd run`'s default, rel_tolerance 1e-4 (--rtol).
// Usage: rollout_timing <problem> [--method M] [--steps K] [--repeat R] [--threads T] [--rtol R] [--backward]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "problem.h"
#include "problem_registry.h"

namespace diffpd {
namespace {

using Clock = std::chrono::steady_clock;

double Median(std::vector<double> t) {
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

int Main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: rollout_timing <problem> [--method M] [--steps K] [--repeat R] [--threads T] [--rtol R] "
                 "[--backward]\n");
    return 2;
  }
  const auto problem = problems::MakeProblem(argv[1]);
  SolverOptions options;
  options.time_step = problem->default_time_step();
  options.rel_tolerance = 1e-4;
  int steps = problem->default_steps(), repeat = 5;
  bool backward = false;
  for (int i = 2; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--method" && has_value) {
      options.method = ParseMethod(argv[++i]);
    } else if (arg == "--steps" && has_value) {
      steps = std::stoi(argv[++i]);
    } else if (arg == "--repeat" && has_value) {
      repeat = std::max(1, std::stoi(argv[++i]));
    } else if (arg == "--threads" && has_value) {
      options.num_threads = std::stoi(argv[++i]);
    } else if (arg == "--rtol" && has_value) {
      options.rel_tolerance = std::stod(argv[++i]);
    } else if (arg == "--backward") {
      backward = true;
    } else {
      std::fprintf(stderr, "rollout_timing: unknown argument '%s'\n", arg.c_str());
      return 2;
    }
  }
  Simulator sim(problem->MakeScene(), options);
  const State initial = problem->InitialState(sim);
  const std::vector<StepInput> inputs = problem->Inputs(sim, steps);
  LossGradient loss(steps);
  loss.dx.back() = VectorXd::Ones(sim.num_dofs());

  Rollout warm = sim.Simulate(initial, inputs);
  if (backward) sim.Backward(warm, loss);
  std::vector<double> forward_seconds, backward_seconds, forward_inner, backward_inner;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = Clock::now();
    const Rollout rollout = sim.Simulate(initial, inputs);
    forward_seconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
    forward_inner.push_back(rollout.forward_seconds());
    if (backward) {
      const auto t1 = Clock::now();
      const RolloutGradient gradient = sim.Backward(rollout, loss);
      backward_seconds.push_back(std::chrono::duration<double>(Clock::now() - t1).count());
      backward_inner.push_back(gradient.report.seconds);
    }
  }
  nlohmann::json out = {
      {"problem", problem->name()}, {"method", ToString(options.method)}, {"steps", steps},
      {"dofs", sim.num_dofs()},     {"forward_seconds", forward_seconds}, {"forward_median", Median(forward_seconds)}};
  out["forward_inner_seconds"] = forward_inner;
  if (backward) {
    out["backward_seconds"] = backward_seconds;
    out["backward_inner_seconds"] = backward_inner;
    out["backward_median"] = Median(backward_seconds);
  }
  std::printf("%s\n", out.dump().c_str());
  return 0;
}

}  // namespace
}  // namespace diffpd

int main(int argc, char** argv) {
  try {
    return diffpd::Main(argc, argv);
  } catch (const diffpd::InvalidInputError& e) {
    std::fprintf(stderr, "rollout_timing: %s\n", e.what());
    return 2;
  } catch (const diffpd::SolverError& e) {
    std::fprintf(stderr, "rollout_timing: %s\n", e.what());
    return 3;
  }
}
