// Benchmark (not a test): time per step and memory of the backward pass
// against the horizon, stored rollout (Simulator::Simulate + Backward) vs
// checkpointed rollout (SimulateCheckpointed + Backward, checkpointed_rollout.h).
// Modes: "stored" (the default options, warm SVDs), "stored-cold" (stored with
// SolverOptions::svd_warm_start = false, as a checkpointed rollout always
// runs: the same gradient bit for bit) and "checkpointed".
//
// Scene: the registered cantilever (8019 DoFs; --refine d doubles its cells
// d times, negative halves them), its initial twist released, pd-lbfgs at
// --rtol (default 1e-4) with the iterative adjoint, --threads threads
// (default 2), h = 10 ms, no inputs. Loss: the random linear loss of
// `diffpd bench` on the final state (problems/tools/bench.h); the
// checkpointed backward passes its per-step force gradients on
// (StateLossGradient::step_gradient) instead of keeping them.
//
// Every case (horizon x mode) runs in a child process of its own, so its
// peak resident set size (getrusage's ru_maxrss of the child, the whole
// process: libraries, the simulator and its PD factor included) is its own.
// A baseline child builds the simulator and takes one step (the factor):
// peak RSS minus the baseline is the rollout's share. "State bytes" counts
// the states held at once: (K + 1) x 2 x 3n doubles stored, and
// BackwardReport::peak_states x 2 x 3n checkpointed. Time per step: (forward
// + backward wall seconds) / K. The target rows compare the checkpointed
// rollout at the longest horizon with the stored one at the shortest.
//
// Usage: checkpoint_benchmark [--horizons 100,1000,10000]
//   [--modes stored,stored-cold,checkpointed] [--checkpoints 48] [--threads 2]
//   [--rtol 1e-4] [--refine 0] [--json]
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/simulator.h"
#include "problem_registry.h"
#include "tools/bench.h"

namespace diffpd {
namespace {

using Clock = std::chrono::steady_clock;
using nlohmann::json;

struct Settings {
  std::vector<int> horizons = {100, 1000, 10000};
  std::vector<std::string> modes = {"stored", "stored-cold", "checkpointed"};
  int checkpoints = 48;
  int threads = 2;
  double rtol = 1e-4;
  int refine = 0;
  bool json_out = false;
};

// One case's measurements ("baseline": one step, no backward).
struct CaseResult {
  std::string mode;
  int horizon = 0;
  int dofs = 0;
  double forward_s = 0, backward_s = 0;
  long recomputed_steps = 0;
  int peak_states = 0;
  double state_bytes = 0;
  double peak_rss_bytes = 0;
  double gradient_norm = 0;  // |dL/dx_0|
  std::string failure;
  double ms_per_step() const { return horizon > 0 ? 1e3 * (forward_s + backward_s) / horizon : 0; }
};

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Runs one case in this (child) process.
CaseResult RunCase(const Settings& s, const std::string& mode, int horizon) {
  CaseResult out;
  out.mode = mode;
  out.horizon = horizon;
  const auto problem = problems::MakeRefinedProblem("cantilever", s.refine);
  SolverOptions options;
  options.method = Method::kPdLbfgs;
  options.time_step = problem->default_time_step();
  options.rel_tolerance = s.rtol;
  options.num_threads = s.threads;
  options.adjoint_solver = AdjointSolver::kIterative;
  options.svd_warm_start = mode != "stored-cold";
  Simulator sim(problem->MakeScene(), options);
  out.dofs = sim.num_dofs();
  const State initial = problem->InitialState(sim);
  const problems::LinearLoss loss = problems::LinearLoss::Random(sim.num_dofs(), 1);
  const double state_doubles = 2.0 * sim.num_dofs();
  if (mode == "baseline") {
    sim.Step(initial, StepInput());
    return out;
  }
  const std::vector<StepInput> inputs(horizon);
  if (mode == "stored" || mode == "stored-cold") {
    auto start = Clock::now();
    const Rollout r = sim.Simulate(initial, inputs);
    out.forward_s = Seconds(start);
    LossGradient dl(horizon);
    dl.dx[horizon] = loss.cx;
    dl.dv[horizon] = loss.cv;
    start = Clock::now();
    const RolloutGradient g = sim.Backward(r, dl);
    out.backward_s = Seconds(start);
    out.gradient_norm = g.x0.norm();
    out.peak_states = horizon + 1;
  } else {
    CheckpointOptions c;
    c.num_checkpoints = s.checkpoints;
    auto start = Clock::now();
    const CheckpointedRollout r = sim.SimulateCheckpointed(initial, inputs, c);
    out.forward_s = Seconds(start);
    StateLossGradient dl;
    dl.state_gradient = [&loss, horizon](int k, const State&, VectorXd* dx, VectorXd* dv) {
      if (k != horizon) return;
      *dx = loss.cx;
      *dv = loss.cv;
    };
    dl.step_gradient = [](int, const VectorXd&, const VectorXd&) {};
    start = Clock::now();
    const RolloutGradient g = sim.Backward(r, dl);
    out.backward_s = Seconds(start);
    out.gradient_norm = g.x0.norm();
    out.recomputed_steps = g.report.recomputed_steps;
    out.peak_states = g.report.peak_states;
  }
  out.state_bytes = out.peak_states * state_doubles * sizeof(double);
  return out;
}

json ToJson(const CaseResult& r) {
  return {{"mode", r.mode},
          {"horizon", r.horizon},
          {"dofs", r.dofs},
          {"forward_s", r.forward_s},
          {"backward_s", r.backward_s},
          {"ms_per_step", r.ms_per_step()},
          {"recomputed_steps", r.recomputed_steps},
          {"peak_states", r.peak_states},
          {"state_bytes", r.state_bytes},
          {"peak_rss_bytes", r.peak_rss_bytes},
          {"gradient_norm", r.gradient_norm},
          {"failure", r.failure}};
}

CaseResult FromJson(const json& j) {
  CaseResult r;
  r.mode = j.at("mode");
  r.horizon = j.at("horizon");
  r.dofs = j.at("dofs");
  r.forward_s = j.at("forward_s");
  r.backward_s = j.at("backward_s");
  r.recomputed_steps = j.at("recomputed_steps");
  r.peak_states = j.at("peak_states");
  r.state_bytes = j.at("state_bytes");
  r.gradient_norm = j.at("gradient_norm");
  r.failure = j.at("failure");
  return r;
}

// Runs one case in a child process; the child's peak RSS is the case's.
CaseResult RunInChild(const Settings& s, const std::string& mode, int horizon) {
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    close(fds[0]);
    CaseResult r;
    try {
      r = RunCase(s, mode, horizon);
    } catch (const std::exception& e) {
      r.mode = mode;
      r.horizon = horizon;
      r.failure = e.what();
    }
    const std::string text = ToJson(r).dump();
    size_t written = 0;
    while (written < text.size()) {
      const ssize_t w = write(fds[1], text.data() + written, text.size() - written);
      if (w <= 0) break;
      written += static_cast<size_t>(w);
    }
    close(fds[1]);
    _exit(0);
  }
  close(fds[1]);
  std::string text;
  char buffer[4096];
  ssize_t got;
  while ((got = read(fds[0], buffer, sizeof buffer)) > 0) text.append(buffer, static_cast<size_t>(got));
  close(fds[0]);
  int status = 0;
  rusage usage{};
  wait4(pid, &status, 0, &usage);
  CaseResult r;
  if (text.empty()) {
    r.mode = mode;
    r.horizon = horizon;
    r.failure = "the case's process ended without a result (status " + std::to_string(status) + ")";
  } else {
    r = FromJson(json::parse(text));
  }
  r.peak_rss_bytes = 1024.0 * usage.ru_maxrss;  // Linux: kilobytes
  return r;
}

struct BenchmarkResult {
  Settings settings;
  CaseResult baseline;
  std::vector<CaseResult> cases;
};

BenchmarkResult Run(const Settings& s) {
  BenchmarkResult out;
  out.settings = s;
  out.baseline = RunInChild(s, "baseline", 0);
  for (int horizon : s.horizons)
    for (const std::string& mode : s.modes) {
      out.cases.push_back(RunInChild(s, mode, horizon));
      std::cerr << mode << " " << horizon << ": " << out.cases.back().ms_per_step() << " ms/step\n";
    }
  return out;
}

const CaseResult* Find(const BenchmarkResult& r, const std::string& mode, int horizon) {
  for (const CaseResult& c : r.cases)
    if (c.mode == mode && c.horizon == horizon && c.failure.empty()) return &c;
  return nullptr;
}

void PrintTable(const BenchmarkResult& r, std::ostream& os) {
  const double mib = 1024.0 * 1024.0;
  char line[512];
  os << "cantilever (" << r.baseline.dofs << " DoFs), pd-lbfgs rtol " << r.settings.rtol << ", " << r.settings.threads
     << " threads, " << r.settings.checkpoints << " checkpoints; baseline peak RSS " << r.baseline.peak_rss_bytes / mib
     << " MiB\n";
  os << "| mode | steps | ms/step | forward s | backward s | recomputed | states held | state MiB | peak RSS MiB | "
        "RSS - baseline MiB |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const CaseResult& c : r.cases) {
    if (!c.failure.empty()) {
      os << "| " << c.mode << " | " << c.horizon << " | failed: " << c.failure << " |\n";
      continue;
    }
    std::snprintf(line, sizeof line, "| %s | %d | %.1f | %.1f | %.1f | %ld | %d | %.1f | %.1f | %.1f |\n",
                  c.mode.c_str(), c.horizon, c.ms_per_step(), c.forward_s, c.backward_s, c.recomputed_steps,
                  c.peak_states, c.state_bytes / mib, c.peak_rss_bytes / mib,
                  (c.peak_rss_bytes - r.baseline.peak_rss_bytes) / mib);
    os << line;
  }
  const int shortest = r.settings.horizons.front(), longest = r.settings.horizons.back();
  const CaseResult* stored = Find(r, "stored", shortest);
  const CaseResult* checkpointed = Find(r, "checkpointed", longest);
  if (stored && checkpointed) {
    std::snprintf(line, sizeof line,
                  "checkpointed at %d steps vs stored at %d: state bytes x%.3f, peak RSS x%.3f (above baseline "
                  "x%.3f), time per step x%.2f\n",
                  longest, shortest, checkpointed->state_bytes / stored->state_bytes,
                  checkpointed->peak_rss_bytes / stored->peak_rss_bytes,
                  (checkpointed->peak_rss_bytes - r.baseline.peak_rss_bytes) /
                      (stored->peak_rss_bytes - r.baseline.peak_rss_bytes),
                  checkpointed->ms_per_step() / stored->ms_per_step());
    os << line;
  }
  for (int horizon : r.settings.horizons) {
    const CaseResult* b = Find(r, "checkpointed", horizon);
    if (!b) continue;
    os << horizon << " steps: |dL/dx_0| checkpointed " << b->gradient_norm;
    if (const CaseResult* cold = Find(r, "stored-cold", horizon))
      os << ", stored-cold " << cold->gradient_norm
         << (cold->gradient_norm == b->gradient_norm ? " (identical)" : " (differ)");
    if (const CaseResult* warm = Find(r, "stored", horizon))
      os << ", stored " << warm->gradient_norm << " (relative difference "
         << std::abs(warm->gradient_norm - b->gradient_norm) / warm->gradient_norm << ")";
    os << "\n";
  }
}

json ToJson(const BenchmarkResult& r) {
  json j;
  j["settings"] = {
      {"horizons", r.settings.horizons}, {"modes", r.settings.modes}, {"checkpoints", r.settings.checkpoints},
      {"threads", r.settings.threads},   {"rtol", r.settings.rtol},   {"refine", r.settings.refine}};
  j["baseline"] = ToJson(r.baseline);
  j["cases"] = json::array();
  for (const CaseResult& c : r.cases) j["cases"].push_back(ToJson(c));
  return j;
}

template <typename T>
std::vector<T> ParseList(const std::string& text) {
  std::vector<T> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    std::stringstream one(item);
    T v;
    one >> v;
    out.push_back(v);
  }
  return out;
}

}  // namespace
}  // namespace diffpd

int main(int argc, char** argv) {
  using namespace diffpd;
  Settings s;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--horizons") {
      s.horizons = ParseList<int>(next());
    } else if (a == "--modes") {
      s.modes = ParseList<std::string>(next());
    } else if (a == "--checkpoints") {
      s.checkpoints = std::stoi(next());
    } else if (a == "--threads") {
      s.threads = std::stoi(next());
    } else if (a == "--rtol") {
      s.rtol = std::stod(next());
    } else if (a == "--refine") {
      s.refine = std::stoi(next());
    } else if (a == "--json") {
      s.json_out = true;
    } else {
      std::cerr << "usage: checkpoint_benchmark [--horizons 100,1000,10000] [--modes stored,stored-cold,checkpointed] "
                   "[--checkpoints 48] [--threads 2] [--rtol 1e-4] [--refine 0] [--json]\n";
      return 2;
    }
  }
  if (s.horizons.empty()) {
    std::cerr << "--horizons needs at least one horizon\n";
    return 2;
  }
  const BenchmarkResult r = Run(s);
  if (s.json_out)
    std::cout << ToJson(r).dump(2) << "\n";
  else
    PrintTable(r, std::cout);
  return 0;
}
