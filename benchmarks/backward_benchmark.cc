// Benchmark (not a test): the backward pass against the forward, per adjoint
// solver, next to the Newton baselines, at the paper's sizes.
//
// Scenes: the paper's routing tendon (Table row 6, DiffPD Sec. 7.2): a
// 0.1 x 0.1 x 0.8 m column of 4 x 4 x 32 hexahedra (825 nodes, 2475 DoFs),
// E = 5e5 Pa, nu = 0.45, rho = 1e3 kg/m^3, pd-corotated + pd-volume, the 25
// nodes at z = 0 clamped, no gravity or contact; every element a muscle with
// fibre (0, 0, 1) and k = 1e5 Pa, in 16 activation groups (x half, y half,
// z segment of 8 cells), held at the paper's initial guess (16 draws of
// U(0, 2) after seed 42) for 100 steps of 10 ms. The registered cantilever
// (8019 DoFs, 25 steps) and rolling sphere (2469 DoFs, frictional contact,
// 100 steps of 5 ms).
//
// Rows: pd-lbfgs with each adjoint solver (iterative at the old fixed
// tolerance 1e-10, iterative, direct and auto at the default tolerance),
// newton-cholesky, newton-pcg and newton-ldlt (the paper's Newton). Each
// row is one rollout at rel_tolerance --rtol (default 1e-4) and the
// reverse-mode gradient of the random linear loss of `diffpd bench`; the
// gradient (initial state, material, activations) is compared with
// newton-cholesky at rel_tolerance 1e-10 and a direct adjoint. Times are
// medians of --repeat runs (default 3) on fresh simulators, the rows of one
// repetition run one after another (so that a change of machine load hits
// all rows alike), for each thread count of --threads (default 1,2).
//
// --sweep: the adjoint's accuracy against its cost instead. Per scene and
// forward rel_tolerance (1e-3 ... 1e-6), one pd-lbfgs rollout and its
// gradient by the iterative adjoint at fixed tolerances (1e-2 ... 1e-10), by
// the rule backward_rel_tolerance = 0 at several factors, and by the direct
// adjoint (exact: the error the forward alone leaves); seconds, iterations
// per step and the gradient's relative error against the reference.
//
// Usage: backward_benchmark [--scenes tendon,cantilever,rolling-sphere]
//   [--threads 1,2] [--repeat 3] [--rtol 1e-4] [--steps K] [--no-newton]
//   [--sweep] [--json]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/box_mesh.h"
#include "diffpd/simulator.h"
#include "problem_registry.h"
#include "tools/bench.h"

namespace diffpd {
namespace {

using problems::LinearLoss;
using problems::MeasureRollout;
using problems::RelativeError;
using problems::RolloutMeasurement;

// A scene with its rollout.
struct Workload {
  std::string name;
  Scene scene;
  State initial;
  std::vector<StepInput> inputs;
  double time_step = 0;
};

Workload PaperTendon(int steps) {
  Workload w;
  w.name = "tendon";
  w.time_step = 0.01;
  Scene& scene = w.scene;
  const int nx = 4, ny = 4, nz = 32;
  scene.mesh = MakeBoxHexMesh(Eigen::Vector3i(nx, ny, nz), Vec3(0.1, 0.1, 0.8));
  scene.material.youngs_modulus = 5e5;
  scene.material.poissons_ratio = 0.45;
  scene.material.density = 1e3;
  scene.energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  std::vector<int> base;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) <= 1e-9) base.push_back(i);
  FixNodes(&scene, base);
  // Group (2 (x / 2) + y / 2) 4 + z / 8 of cell (x, y, z), element (x ny + y) nz + z.
  scene.muscles.resize(16);
  for (Muscle& m : scene.muscles) {
    m.fibers = {Vec3(0, 0, 1)};
    m.stiffness = 1e5;
  }
  for (int x = 0; x < nx; ++x)
    for (int y = 0; y < ny; ++y)
      for (int z = 0; z < nz; ++z)
        scene.muscles[(2 * (x / 2) + y / 2) * 4 + z / 8].elements.push_back((x * ny + y) * nz + z);
  VectorXd activation(16);
  activation << 0.749080, 1.901429, 1.463988, 1.197317, 0.312037, 0.311989, 0.116167, 1.732352, 1.202230, 1.416145,
      0.041169, 1.939820, 1.664885, 0.424678, 0.363650, 0.366809;
  w.inputs.assign(steps > 0 ? steps : 100, StepInput{VectorXd(), activation});
  SolverOptions options;
  w.initial = Simulator(scene, options).RestState();
  return w;
}

Workload Registered(const std::string& name, int steps) {
  Workload w;
  w.name = name;
  const std::unique_ptr<problems::Problem> problem = problems::MakeProblem(name);
  w.scene = problem->MakeScene();
  w.time_step = problem->default_time_step();
  SolverOptions options;
  options.time_step = w.time_step;
  Simulator sim(w.scene, options);
  w.initial = problem->InitialState(sim);
  w.inputs = problem->Inputs(sim, steps > 0 ? steps : problem->default_steps());
  return w;
}

struct Config {
  std::string name;
  SolverOptions options;
};

std::vector<Config> Configs(double rtol, int threads, double dt, bool newton) {
  auto make = [&](Method method) {
    SolverOptions o;
    o.method = method;
    o.time_step = dt;
    o.rel_tolerance = rtol;
    o.num_threads = threads;
    return o;
  };
  std::vector<Config> configs;
  SolverOptions o = make(Method::kPdLbfgs);
  o.adjoint_solver = AdjointSolver::kIterative;
  o.backward_rel_tolerance = 1e-10;
  configs.push_back({"pd-lbfgs iterative 1e-10", o});
  o = make(Method::kPdLbfgs);
  o.adjoint_solver = AdjointSolver::kIterative;
  configs.push_back({"pd-lbfgs iterative", o});
  o.adjoint_solver = AdjointSolver::kDirect;
  configs.push_back({"pd-lbfgs direct", o});
  o.adjoint_solver = AdjointSolver::kAuto;
  configs.push_back({"pd-lbfgs auto", o});
  if (newton)
    for (Method m : {Method::kNewtonCholesky, Method::kNewtonPcg, Method::kNewtonLdlt})
      configs.push_back({ToString(m), make(m)});
  return configs;
}

struct Row {
  std::string scene, config, failure;
  int threads = 0, steps = 0, dofs = 0;
  double forward_s = 0, backward_s = 0;
  double forward_iters_per_step = 0, backward_iters_per_step = 0;
  int iterative_steps = 0, direct_steps = 0, fallbacks = 0;
  double grad_rel_error = 0;
  std::vector<std::pair<std::string, double>> grad_rel_error_by_part;
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

std::vector<std::pair<std::string, double>> PartErrors(const VectorXd& g, const VectorXd& ref, int n) {
  std::vector<std::pair<std::string, double>> parts = {
      {"x0", RelativeError(g.head(n), ref.head(n))},
      {"v0", RelativeError(g.segment(n, n), ref.segment(n, n))},
      {"material", RelativeError(g.segment(2 * n, 3), ref.segment(2 * n, 3))}};
  const Eigen::Index activations = ref.size() - (2 * n + 3);
  if (activations > 0) parts.push_back({"activation", RelativeError(g.tail(activations), ref.tail(activations))});
  return parts;
}

std::vector<Row> MeasureWorkload(const Workload& w, const std::vector<int>& thread_counts, int repeat, double rtol,
                                 bool newton) {
  const int n = w.scene.mesh.num_dofs(), steps = static_cast<int>(w.inputs.size());
  const LinearLoss loss = LinearLoss::Random(n, 20211);
  SolverOptions ref;
  ref.method = Method::kNewtonCholesky;
  ref.time_step = w.time_step;
  ref.rel_tolerance = problems::kReferenceRelTolerance;
  ref.num_threads = thread_counts.back();
  std::cerr << "[backward] " << w.name << ": " << n << " DoFs, " << steps << " steps; reference" << std::endl;
  const RolloutMeasurement reference = MeasureRollout(w.scene, ref, w.initial, w.inputs, loss, 1);
  if (!reference.ok()) throw SolverError(reference.status, "the reference failed: " + reference.failure);
  std::vector<Row> rows;
  for (const int threads : thread_counts) {
    const std::vector<Config> configs = Configs(rtol, threads, w.time_step, newton);
    std::vector<std::vector<RolloutMeasurement>> runs(configs.size());
    for (int r = 0; r < repeat; ++r)
      for (size_t c = 0; c < configs.size(); ++c) {
        runs[c].push_back(MeasureRollout(w.scene, configs[c].options, w.initial, w.inputs, loss, 1));
        const RolloutMeasurement& m = runs[c].back();
        std::cerr << "[backward] " << w.name << " " << threads << " threads, run " << r + 1 << ": " << configs[c].name
                  << ": " << (m.ok() ? "" : m.failure) << m.forward_s << " s + " << m.backward_s << " s" << std::endl;
      }
    for (size_t c = 0; c < configs.size(); ++c) {
      Row row;
      row.scene = w.name;
      row.config = configs[c].name;
      row.threads = threads;
      row.steps = steps;
      row.dofs = n;
      std::vector<double> forward, backward;
      for (const RolloutMeasurement& m : runs[c]) {
        if (!m.ok()) {
          row.failure = m.failure;
          break;
        }
        forward.push_back(m.forward_s);
        backward.push_back(m.backward_s);
      }
      if (row.failure.empty()) {
        const RolloutMeasurement& last = runs[c].back();
        row.forward_s = Median(forward);
        row.backward_s = Median(backward);
        row.forward_iters_per_step = last.iters_per_step;
        row.backward_iters_per_step = double(last.backward_iterations) / steps;
        row.iterative_steps = last.backward_iterative_steps;
        row.direct_steps = last.backward_direct_steps;
        row.fallbacks = last.backward_fallbacks;
        row.grad_rel_error = RelativeError(last.gradient, reference.gradient);
        row.grad_rel_error_by_part = PartErrors(last.gradient, reference.gradient, n);
      }
      rows.push_back(row);
    }
  }
  return rows;
}

// One backward variant of the sweep on one forward rollout.
struct SweepRow {
  std::string scene, adjoint;
  double forward_rel_tolerance = 0;
  double forward_s = 0, forward_iters_per_step = 0;
  double backward_s = 0, backward_iters_per_step = 0;
  double grad_rel_error = 0;
  double part_max = 0;
};

std::vector<SweepRow> Sweep(const Workload& w, int threads) {
  const int n = w.scene.mesh.num_dofs(), steps = static_cast<int>(w.inputs.size());
  const LinearLoss loss = LinearLoss::Random(n, 20211);
  SolverOptions ref;
  ref.method = Method::kNewtonCholesky;
  ref.time_step = w.time_step;
  ref.rel_tolerance = problems::kReferenceRelTolerance;
  ref.num_threads = threads;
  std::cerr << "[sweep] " << w.name << ": reference" << std::endl;
  const RolloutMeasurement reference = MeasureRollout(w.scene, ref, w.initial, w.inputs, loss, 1);
  if (!reference.ok()) throw SolverError(reference.status, "the reference failed: " + reference.failure);
  LossGradient dl(steps);
  dl.dx[steps] = loss.cx;
  dl.dv[steps] = loss.cv;
  std::vector<SweepRow> rows;
  for (const double forward_tol : {1e-3, 1e-4, 1e-5, 1e-6}) {
    SolverOptions o;
    o.method = Method::kPdLbfgs;
    o.time_step = w.time_step;
    o.rel_tolerance = forward_tol;
    o.num_threads = threads;
    Simulator sim(w.scene, o);
    auto start = std::chrono::steady_clock::now();
    const Rollout rollout = sim.Simulate(w.initial, w.inputs);
    const double forward_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    long forward_iterations = 0;
    for (const StepReport& r : rollout.reports) forward_iterations += r.iterations;
    struct Variant {
      std::string name;
      AdjointSolver solver;
      double tolerance, factor;
    };
    std::vector<Variant> variants;
    for (const double t : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-10}) {
      std::ostringstream name;
      name << "fixed " << t;
      variants.push_back({name.str(), AdjointSolver::kIterative, t, 0.01});
    }
    for (const double f : {0.1, 0.03, 0.01, 0.001}) {
      std::ostringstream name;
      name << "rule x" << f;
      variants.push_back({name.str(), AdjointSolver::kIterative, 0.0, f});
    }
    variants.push_back({"direct", AdjointSolver::kDirect, 0.0, 0.01});
    for (const Variant& v : variants) {
      SolverOptions b = o;
      b.adjoint_solver = v.solver;
      b.backward_rel_tolerance = v.tolerance;
      b.backward_tolerance_factor = v.factor;
      sim.SetOptions(b);
      start = std::chrono::steady_clock::now();
      const RolloutGradient g = sim.Backward(rollout, dl);
      SweepRow row;
      row.backward_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      row.scene = w.name;
      row.adjoint = v.name;
      row.forward_rel_tolerance = forward_tol;
      row.forward_s = forward_s;
      row.forward_iters_per_step = double(forward_iterations) / steps;
      row.backward_iters_per_step = double(g.report.linear_iterations) / steps;
      VectorXd stacked(reference.gradient.size());
      stacked.head(2 * n + 3) << g.x0, g.v0, g.youngs_modulus, g.poissons_ratio, g.density;
      Eigen::Index at = 2 * n + 3;
      for (const VectorXd& a : g.activation) {
        stacked.segment(at, a.size()) = a;
        at += a.size();
      }
      row.grad_rel_error = RelativeError(stacked, reference.gradient);
      for (const auto& p : PartErrors(stacked, reference.gradient, n)) row.part_max = std::max(row.part_max, p.second);
      std::cerr << "[sweep] " << w.name << " rtol " << forward_tol << " " << v.name << ": " << row.grad_rel_error
                << std::endl;
      rows.push_back(row);
    }
  }
  return rows;
}

const Row* Find(const std::vector<Row>& rows, const Row& like, const std::string& config) {
  for (const Row& r : rows)
    if (r.scene == like.scene && r.threads == like.threads && r.config == config && r.failure.empty()) return &r;
  return nullptr;
}

// (forward + backward) of the faster of newton-cholesky and newton-pcg over
// the row's, and of newton-ldlt over the row's.
void Ratios(const std::vector<Row>& rows, const Row& row, double* vs_best_newton, double* vs_ldlt) {
  const double total = row.forward_s + row.backward_s;
  double best = std::numeric_limits<double>::infinity();
  for (const char* m : {"newton-cholesky", "newton-pcg"})
    if (const Row* r = Find(rows, row, m)) best = std::min(best, r->forward_s + r->backward_s);
  *vs_best_newton = std::isfinite(best) ? best / total : 0;
  const Row* ldlt = Find(rows, row, "newton-ldlt");
  *vs_ldlt = ldlt ? (ldlt->forward_s + ldlt->backward_s) / total : 0;
}

void PrintTable(const std::vector<Row>& rows) {
  std::printf("%-15s %3s %-26s %9s %9s %7s %8s %8s %9s %10s %10s %9s %9s\n", "scene", "thr", "config", "forward_s",
              "backward_s", "bwd/fwd", "fwd_it", "bwd_it", "iter/dir", "grad_err", "part_max", "xNewton", "xLDLT");
  for (const Row& r : rows) {
    if (!r.failure.empty()) {
      std::printf("%-15s %3d %-26s failed: %s\n", r.scene.c_str(), r.threads, r.config.c_str(), r.failure.c_str());
      continue;
    }
    double part_max = 0;
    for (const auto& p : r.grad_rel_error_by_part) part_max = std::max(part_max, p.second);
    double vs_newton = 0, vs_ldlt = 0;
    Ratios(rows, r, &vs_newton, &vs_ldlt);
    char split[32];
    std::snprintf(split, sizeof(split), "%d/%d", r.iterative_steps, r.direct_steps);
    std::printf("%-15s %3d %-26s %9.3f %9.3f %7.2f %8.1f %8.1f %9s %10.2e %10.2e %9.2f %9.2f\n", r.scene.c_str(),
                r.threads, r.config.c_str(), r.forward_s, r.backward_s, r.backward_s / r.forward_s,
                r.forward_iters_per_step, r.backward_iters_per_step, split, r.grad_rel_error, part_max, vs_newton,
                vs_ldlt);
  }
}

nlohmann::json ToJson(const std::vector<Row>& rows, double rtol, int repeat) {
  nlohmann::json out = nlohmann::json::array();
  for (const Row& r : rows) {
    nlohmann::json j = {
        {"scene", r.scene},     {"config", r.config},
        {"threads", r.threads}, {"steps", r.steps},
        {"dofs", r.dofs},       {"rel_tolerance", rtol},
        {"repeat", repeat},     {"status", r.failure.empty() ? std::string("ok") : "failed: " + r.failure}};
    if (r.failure.empty()) {
      double vs_newton = 0, vs_ldlt = 0;
      Ratios(rows, r, &vs_newton, &vs_ldlt);
      j["forward_s"] = r.forward_s;
      j["backward_s"] = r.backward_s;
      j["backward_over_forward"] = r.backward_s / r.forward_s;
      j["forward_iters_per_step"] = r.forward_iters_per_step;
      j["backward_iters_per_step"] = r.backward_iters_per_step;
      j["iterative_steps"] = r.iterative_steps;
      j["direct_steps"] = r.direct_steps;
      j["fallbacks"] = r.fallbacks;
      j["grad_rel_error"] = r.grad_rel_error;
      nlohmann::json parts = nlohmann::json::object();
      for (const auto& p : r.grad_rel_error_by_part) parts[p.first] = p.second;
      j["grad_rel_error_by_part"] = parts;
      j["speedup_vs_best_newton"] = vs_newton > 0 ? nlohmann::json(vs_newton) : nlohmann::json(nullptr);
      j["speedup_vs_newton_ldlt"] = vs_ldlt > 0 ? nlohmann::json(vs_ldlt) : nlohmann::json(nullptr);
    }
    out.push_back(j);
  }
  return out;
}

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) out.push_back(item);
  return out;
}

void PrintSweep(const std::vector<SweepRow>& rows) {
  std::printf("%-15s %9s %-12s %9s %8s %10s %8s %10s %10s\n", "scene", "fwd_rtol", "adjoint", "forward_s", "fwd_it",
              "backward_s", "bwd_it", "grad_err", "part_max");
  for (const SweepRow& r : rows)
    std::printf("%-15s %9.0e %-12s %9.3f %8.1f %10.3f %8.1f %10.2e %10.2e\n", r.scene.c_str(), r.forward_rel_tolerance,
                r.adjoint.c_str(), r.forward_s, r.forward_iters_per_step, r.backward_s, r.backward_iters_per_step,
                r.grad_rel_error, r.part_max);
}

nlohmann::json SweepToJson(const std::vector<SweepRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const SweepRow& r : rows)
    out.push_back({{"scene", r.scene},
                   {"forward_rel_tolerance", r.forward_rel_tolerance},
                   {"adjoint", r.adjoint},
                   {"forward_s", r.forward_s},
                   {"forward_iters_per_step", r.forward_iters_per_step},
                   {"backward_s", r.backward_s},
                   {"backward_iters_per_step", r.backward_iters_per_step},
                   {"grad_rel_error", r.grad_rel_error},
                   {"grad_rel_error_part_max", r.part_max}});
  return out;
}

int Main(int argc, char** argv) {
  std::vector<std::string> scenes = {"tendon", "cantilever", "rolling-sphere"};
  std::vector<int> threads = {1, 2};
  int repeat = 3, steps = -1;
  double rtol = 1e-4;
  bool json = false, newton = true, sweep = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--json") {
      json = true;
    } else if (a == "--no-newton") {
      newton = false;
    } else if (a == "--sweep") {
      sweep = true;
    } else if (a == "--scenes" && has_value) {
      scenes = Split(argv[++i]);
    } else if (a == "--threads" && has_value) {
      threads.clear();
      for (const std::string& t : Split(argv[++i])) threads.push_back(std::stoi(t));
    } else if (a == "--repeat" && has_value) {
      repeat = std::max(1, std::stoi(argv[++i]));
    } else if (a == "--rtol" && has_value) {
      rtol = std::stod(argv[++i]);
    } else if (a == "--steps" && has_value) {
      steps = std::stoi(argv[++i]);
    } else {
      std::fprintf(stderr, "unknown argument '%s'\n", a.c_str());
      return 2;
    }
  }
  if (sweep) {
    std::vector<SweepRow> rows;
    for (const std::string& name : scenes) {
      const std::vector<SweepRow> scene_rows =
          Sweep(name == "tendon" ? PaperTendon(steps) : Registered(name, steps), threads.front());
      rows.insert(rows.end(), scene_rows.begin(), scene_rows.end());
    }
    if (json) {
      std::printf("%s\n", SweepToJson(rows).dump(2).c_str());
    } else {
      std::printf(
          "# pd-lbfgs gradient error against newton-cholesky at rel_tolerance 1e-10, per forward tolerance and "
          "adjoint: the iterative adjoint at a fixed tolerance, by the rule (backward_rel_tolerance 0) with "
          "the factor given, and the direct (exact) adjoint; %d thread(s)\n",
          threads.front());
      PrintSweep(rows);
    }
    return 0;
  }
  std::vector<Row> rows;
  for (const std::string& name : scenes) {
    const Workload w = name == "tendon" ? PaperTendon(steps) : Registered(name, steps);
    const std::vector<Row> scene_rows = MeasureWorkload(w, threads, repeat, rtol, newton);
    rows.insert(rows.end(), scene_rows.begin(), scene_rows.end());
  }
  if (json) {
    std::printf("%s\n", ToJson(rows, rtol, repeat).dump(2).c_str());
  } else {
    std::printf(
        "# rel_tolerance %g, medians of %d runs; bwd/fwd = backward_s / forward_s; fwd_it, bwd_it: iterations "
        "per step; iter/dir: backward steps solved iteratively / directly; grad_err: relative error of the "
        "whole gradient, part_max: the largest over its parts (x0, v0, material, activation); xNewton, "
        "xLDLT: (forward + backward) of the faster of newton-cholesky and newton-pcg, and of newton-ldlt, "
        "over the row's\n",
        rtol, repeat);
    PrintTable(rows);
  }
  return 0;
}

}  // namespace
}  // namespace diffpd

int main(int argc, char** argv) {
  try {
    return diffpd::Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "backward_benchmark: %s\n", e.what());
    return 1;
  }
}
