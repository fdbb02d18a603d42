#include "tools/bench.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <sstream>

#include "scenes/bouncing_ball.h"
#include "scenes/cantilever.h"
#include "scenes/rolling_sphere.h"
#include "diffpd/error.h"
#include "problem_registry.h"
#include "cli/invalid_option.h"

namespace diffpd::problems {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

std::string Failure(const SolverError& e) { return std::string(ToString(e.status())) + ": " + e.what(); }

double PeakRssMib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

// Options of a benchmarked method.
SolverOptions MethodOptions(Method method, const BenchOptions& o, double time_step) {
  SolverOptions s;
  s.method = method;
  s.time_step = time_step;
  s.rel_tolerance = o.rel_tolerance;
  s.backward_rel_tolerance = o.backward_rel_tolerance > 0 ? o.backward_rel_tolerance : 0.0;
  s.adjoint_solver = o.adjoint_solver;
  s.num_threads = o.threads;
  s.max_iterations = o.max_iterations;
  s.lbfgs_weight_scale = o.lbfgs_weight_scale;
  s.rigid_mode_correction = o.rigid_mode_correction;
  if (o.factor_copy_max_gib >= 0) s.pd_factor_copy_max_bytes = o.factor_copy_max_gib * 1073741824.0;
  return s;
}

// A problem instance with everything a measurement needs.
struct Setup {
  std::unique_ptr<Problem> problem;
  Scene scene;
  int steps = 0;
  double time_step = 0;
  State initial;
  std::vector<StepInput> inputs;
  LinearLoss loss;
};

Setup MakeSetup(const std::string& name, int doublings, const BenchOptions& o) {
  Setup s;
  s.problem = MakeRefinedProblem(name, doublings, o.cantilever_cells);
  s.scene = s.problem->MakeScene();
  s.steps = o.steps > 0 ? o.steps : s.problem->default_steps();
  s.time_step = o.time_step > 0 ? o.time_step : s.problem->default_time_step();
  Simulator sim(s.scene, MethodOptions(Method::kNewtonCholesky, o, s.time_step));
  s.initial = s.problem->InitialState(sim);
  s.inputs = s.problem->Inputs(sim, s.steps);
  s.loss = LinearLoss::Random(sim.num_dofs(), o.seed);
  return s;
}

void Progress(std::ostream* out, const std::string& line) {
  if (out) *out << line << std::endl;
}

std::string Describe(const RolloutMeasurement& m) {
  std::ostringstream s;
  if (!m.ok()) {
    s << "failed: " << m.failure;
  } else {
    s << "forward " << m.forward_s << " s, backward " << m.backward_s << " s, " << m.iters_per_step
      << " iterations/step";
    if (m.rounding_floor_steps > 0) s << ", " << m.rounding_floor_steps << " steps ended at the rounding floor";
    if (m.newton_fallback_steps > 0) s << ", " << m.newton_fallback_steps << " steps finished by Newton";
  }
  return s.str();
}

nlohmann::json NumberOrNull(bool ok, double v) { return ok ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

std::unique_ptr<Problem> MakeRefinedProblem(const std::string& name, int doublings,
                                            const std::array<int, 3>& cantilever_cells) {
  std::unique_ptr<Problem> problem = MakeProblem(name);  // an unknown name: the list of problems
  const bool own_cells = cantilever_cells != std::array<int, 3>{0, 0, 0};
  if (own_cells) {
    if (name != "cantilever")
      throw InvalidInputError("cells are available for cantilever only, not for '" + name + "'");
    for (int c : cantilever_cells)
      if (c < 1 || c > kMaxCantileverCells) {
        std::ostringstream msg;
        msg << "cells = " << cantilever_cells[0] << "x" << cantilever_cells[1] << "x" << cantilever_cells[2]
            << " is invalid: each count must be in [1, " << kMaxCantileverCells << "]";
        throw InvalidInputError(msg.str());
      }
  }
  if (doublings == 0 && !own_cells) return problem;
  const bool refinable =
      name == "cantilever" || name == "falling-cube" || name == "bouncing-ball" || name == "rolling-sphere";
  if (refinable && (doublings < kMinRefinement || doublings > kMaxRefinement)) {
    std::ostringstream msg;
    msg << "refinement = " << doublings << " is invalid for " << name << ": it must be in [" << kMinRefinement << ", "
        << kMaxRefinement << "] (" << kMaxRefinement << ": " << (1 << kMaxRefinement) << " times the cells)";
    throw InvalidInputError(msg.str());
  }
  if (name == "cantilever") {
    std::array<int, 3> cells = own_cells ? cantilever_cells : std::array<int, 3>{32, 8, 8};
    for (int i = 0; i < std::abs(doublings); ++i) {
      const int axis = doublings > 0 ? i % 3 : 2 - i % 3;
      if (doublings > 0) {
        cells[axis] *= 2;
      } else {
        cells[axis] = std::max(1, cells[axis] / 2);  // 32 x 8 x 8 halves 9 times, to 4 x 1 x 1
      }
    }
    return std::make_unique<Cantilever>(cells[0], cells[1], cells[2]);
  }
  // Cells per axis of a cubic grid of `base` cells per axis, scaled to
  // 2^doublings times the cells (at least one).
  auto per_axis = [&](double base) {
    return std::max(1, static_cast<int>(std::lround(base * std::pow(2.0, doublings / 3.0))));
  };
  if (name == "falling-cube") return std::make_unique<FallingCube>(per_axis(8));
  if (name == "bouncing-ball") return std::make_unique<BouncingBall>(per_axis(BouncingBall::kCells));
  if (name == "rolling-sphere")
    return std::make_unique<RollingSphere>(ContactLinearSolve::kWoodbury, per_axis(RollingSphere::kCells));
  throw InvalidInputError("problem '" + name +
                          "' cannot be refined: refinement is available for cantilever, falling-cube, bouncing-ball "
                          "and rolling-sphere");
}

std::array<int, 3> ParseCells(const std::string& text) {
  std::array<int, 3> cells{};
  std::istringstream in(text);
  char x1 = 0, x2 = 0;
  std::string rest;
  if (!(in >> cells[0] >> x1 >> cells[1] >> x2 >> cells[2]) || x1 != 'x' || x2 != 'x' || (in >> rest))
    throw InvalidInputError("cells = '" + text + "' is invalid: must be three cell counts NXxNYxNZ, e.g. 172x43x43");
  return cells;
}

std::vector<Method> ParseMethods(const std::vector<std::string>& names) {
  std::vector<Method> methods;
  for (const auto& name : names) methods.push_back(ParseMethod(name));
  return methods;
}

LinearLoss LinearLoss::Random(int num_dofs, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  LinearLoss l;
  l.cx.resize(num_dofs);
  l.cv.resize(num_dofs);
  for (int i = 0; i < num_dofs; ++i) l.cx(i) = normal(rng);
  for (int i = 0; i < num_dofs; ++i) l.cv(i) = normal(rng);
  return l;
}

RolloutMeasurement MeasureRollout(const Scene& scene, const SolverOptions& options, const State& initial,
                                  const std::vector<StepInput>& inputs, const LinearLoss& loss, int repeat) {
  if (repeat < 1) {
    std::ostringstream msg;
    msg << "repeat = " << repeat << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
  RolloutMeasurement m;
  std::vector<double> forward, backward, factorization;
  const int steps = static_cast<int>(inputs.size());
  for (int r = 0; r < repeat; ++r) {
    Simulator sim(scene, options);
    Rollout rollout;
    try {
      auto start = Clock::now();
      rollout = sim.Simulate(initial, inputs);
      forward.push_back(SecondsSince(start));
      factorization.push_back(sim.pd_factorization_seconds());
      LossGradient dl(steps);
      dl.dx[steps] = loss.cx;
      dl.dv[steps] = loss.cv;
      start = Clock::now();
      const RolloutGradient g = sim.Backward(rollout, dl);
      backward.push_back(SecondsSince(start));
      m.backward_iterations = g.report.linear_iterations;
      m.backward_fallbacks = g.report.fallbacks;
      m.backward_iterative_steps = g.report.iterative_steps;
      m.backward_direct_steps = g.report.direct_steps;
      m.factor_copy_bytes = static_cast<double>(sim.pd_factor_copy_bytes());
      const int n = sim.num_dofs();
      Eigen::Index activations = 0;
      for (const VectorXd& a : g.activation) activations += a.size();
      m.gradient.resize(2 * n + 3 + activations);
      m.gradient.head(2 * n + 3) << g.x0, g.v0, g.youngs_modulus, g.poissons_ratio, g.density;
      Eigen::Index at = 2 * n + 3;
      for (const VectorXd& a : g.activation) {
        m.gradient.segment(at, a.size()) = a;
        at += a.size();
      }
    } catch (const SolverError& e) {
      m.failure = Failure(e);
      m.status = e.status();
      return m;
    }
    m.final_state = rollout.states.back();
    if (!m.final_state.x.allFinite() || !m.final_state.v.allFinite() || !m.gradient.allFinite()) {
      m.failure = "non-finite result returned without an error (a library bug)";
      m.status = SolverStatus::kNonFinite;
      return m;
    }
    m.total_iterations = 0;
    m.rounding_floor_steps = 0;
    m.newton_fallback_steps = 0;
    for (const auto& rep : rollout.reports) {
      m.total_iterations += rep.iterations;
      m.rounding_floor_steps += rep.rounding_floor_stop;
      m.newton_fallback_steps += rep.newton_fallback;
    }
  }
  m.forward_s = Median(forward);
  m.backward_s = Median(backward);
  m.factorization_s = Median(factorization);
  m.iters_per_step = steps > 0 ? double(m.total_iterations) / steps : 0;
  return m;
}

double RelativeError(const VectorXd& a, const VectorXd& ref) {
  const double d = (a - ref).norm(), r = ref.norm();
  return r > 0 ? d / r : d;
}

VectorXd StackState(const State& s) {
  VectorXd out(s.x.size() + s.v.size());
  out << s.x, s.v;
  return out;
}

std::string ThreadRange() {
  return "in [0, " + std::to_string(MaxSolverThreads()) + "] (0: OpenMP default; SolverOptions::num_threads)";
}

void BenchOptions::Validate() const {
  const auto fail = ThrowInvalidOption;
  if (methods.empty()) throw InvalidInputError("methods is empty: name at least one method");
  for (Method m : methods)
    if (m == Method::kSemiImplicit)
      throw InvalidInputError(
          "method semi-implicit is not benchmarked: it has no tolerance (use newton-cholesky, "
          "newton-pcg, newton-ldlt, pd or pd-lbfgs)");
  if (!(rel_tolerance > 0 && rel_tolerance < 1)) fail("rtol", rel_tolerance, "in (0, 1)");
  if (!(backward_rel_tolerance < 1))
    fail("backward rtol", backward_rel_tolerance, "< 1 (<= 0: derived from the forward's accuracy)");
  if (repeat < 1) fail("repeat", repeat, ">= 1");
  if (threads < 0 || threads > MaxSolverThreads()) fail("threads", threads, ThreadRange());
  if (max_iterations < 1) fail("max iterations", max_iterations, ">= 1");
  if (!(lbfgs_weight_scale > 0 && lbfgs_weight_scale <= 1)) fail("lbfgs scale", lbfgs_weight_scale, "in (0, 1]");
  if (!std::isfinite(time_step)) fail("dt", time_step, "finite (> 0, or <= 0 for the default)");
  if (std::isnan(factor_copy_max_gib))
    fail("factor copy max GiB", factor_copy_max_gib, ">= 0, infinity, or < 0 for the library's default");
}

BenchResult RunBench(const std::string& problem, const BenchOptions& options, std::ostream* progress) {
  options.Validate();
  const Setup s = MakeSetup(problem, options.refine, options);
  BenchResult result;
  result.problem = problem;
  result.dofs = s.scene.mesh.num_dofs();
  result.elements = s.scene.mesh.num_elements();
  result.steps = s.steps;
  result.time_step = s.time_step;

  SolverOptions ref = MethodOptions(Method::kNewtonCholesky, options, s.time_step);
  ref.rel_tolerance = kReferenceRelTolerance;
  ref.backward_rel_tolerance = kReferenceBackwardRelTolerance;
  {
    std::ostringstream line;
    line << "[bench] " << problem << ": " << result.elements << " elements, " << result.dofs << " DoFs, " << s.steps
         << " steps of " << s.time_step << " s; reference newton-cholesky rtol " << ref.rel_tolerance;
    Progress(progress, line.str());
  }
  const RolloutMeasurement reference = MeasureRollout(s.scene, ref, s.initial, s.inputs, s.loss, 1);
  if (!reference.ok())
    throw SolverError(reference.status,
                      "the reference (newton-cholesky, rel_tolerance 1e-10) failed: " + reference.failure);
  result.reference_forward_s = reference.forward_s;
  Progress(progress, "[bench] reference: " + Describe(reference));
  const VectorXd ref_state = StackState(reference.final_state);
  const int n = result.dofs;

  for (Method method : options.methods) {
    Progress(progress, std::string("[bench] ") + ToString(method) + " ...");
    RolloutMeasurement m;
    try {
      m = MeasureRollout(s.scene, MethodOptions(method, options, s.time_step), s.initial, s.inputs, s.loss,
                         options.repeat);
    } catch (const InvalidInputError& e) {  // e.g. PD on an energy that is not projective
      m.failure = std::string("invalid input: ") + e.what();
    }
    Progress(progress, std::string("[bench] ") + ToString(method) + ": " + Describe(m));
    BenchRow row;
    row.method = ToString(method);
    row.failure = m.failure;
    if (m.ok()) {
      row.forward_s = m.forward_s;
      row.backward_s = m.backward_s;
      row.iters_per_step = m.iters_per_step;
      row.backward_iters_per_step = result.steps > 0 ? double(m.backward_iterations) / result.steps : 0;
      row.backward_fallbacks = m.backward_fallbacks;
      row.backward_iterative_steps = m.backward_iterative_steps;
      row.backward_direct_steps = m.backward_direct_steps;
      row.rounding_floor_steps = m.rounding_floor_steps;
      row.newton_fallback_steps = m.newton_fallback_steps;
      row.forward_per_iteration_ms = m.total_iterations > 0 ? 1e3 * m.forward_s / m.total_iterations : 0;
      row.factorization_s = m.factorization_s;
      row.state_rel_error = RelativeError(StackState(m.final_state), ref_state);
      row.position_rel_error = RelativeError(m.final_state.x, reference.final_state.x);
      row.velocity_rel_error = RelativeError(m.final_state.v, reference.final_state.v);
      row.grad_rel_error = RelativeError(m.gradient, reference.gradient);
      row.grad_rel_error_by_input["x0"] = RelativeError(m.gradient.head(n), reference.gradient.head(n));
      row.grad_rel_error_by_input["v0"] = RelativeError(m.gradient.segment(n, n), reference.gradient.segment(n, n));
      const char* names[3] = {"youngs_modulus", "poissons_ratio", "density"};
      for (int k = 0; k < 3; ++k)
        row.grad_rel_error_by_input[names[k]] =
            RelativeError(m.gradient.segment(2 * n + k, 1), reference.gradient.segment(2 * n + k, 1));
      const Eigen::Index activations = reference.gradient.size() - (2 * n + 3);
      if (activations > 0)
        row.grad_rel_error_by_input["activation"] =
            RelativeError(m.gradient.tail(activations), reference.gradient.tail(activations));
    }
    result.rows.push_back(row);
  }
  // (forward + backward) of a successful row of `method`, if any.
  const auto total = [&result](Method method) -> std::optional<double> {
    for (const auto& row : result.rows)
      if (row.method == ToString(method) && row.failure.empty()) return row.forward_s + row.backward_s;
    return std::nullopt;
  };
  const std::optional<double> cholesky = total(Method::kNewtonCholesky), pcg = total(Method::kNewtonPcg),
                              ldlt = total(Method::kNewtonLdlt);
  std::optional<double> best = cholesky;
  if (pcg && (!best || *pcg < *best)) best = pcg;
  for (auto& row : result.rows) {
    const double own = row.forward_s + row.backward_s;
    if (!row.failure.empty() || !(own > 0)) continue;
    if (cholesky) row.speedup_vs_newton_cholesky = *cholesky / own;
    if (best) row.speedup_vs_best_newton = *best / own;
    if (ldlt) row.speedup_vs_newton_ldlt = *ldlt / own;
  }
  return result;
}

nlohmann::json BenchToJson(const BenchResult& result, const BenchOptions& options) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : result.rows) {
    const bool ok = r.failure.empty();
    nlohmann::json by_input = nlohmann::json::object();
    for (const auto& [k, v] : r.grad_rel_error_by_input) by_input[k] = v;
    rows.push_back(
        {{"method", r.method},
         {"status", ok ? std::string("ok") : "failed: " + r.failure},
         {"forward_s", NumberOrNull(ok, r.forward_s)},
         {"backward_s", NumberOrNull(ok, r.backward_s)},
         {"iters_per_step", NumberOrNull(ok, r.iters_per_step)},
         {"backward_iters_per_step", NumberOrNull(ok, r.backward_iters_per_step)},
         {"backward_fallbacks", ok ? nlohmann::json(r.backward_fallbacks) : nlohmann::json(nullptr)},
         {"rounding_floor_steps", ok ? nlohmann::json(r.rounding_floor_steps) : nlohmann::json(nullptr)},
         {"newton_fallback_steps", ok ? nlohmann::json(r.newton_fallback_steps) : nlohmann::json(nullptr)},
         {"state_rel_error", NumberOrNull(ok, r.state_rel_error)},
         {"position_rel_error", NumberOrNull(ok, r.position_rel_error)},
         {"velocity_rel_error", NumberOrNull(ok, r.velocity_rel_error)},
         {"grad_rel_error", NumberOrNull(ok, r.grad_rel_error)},
         {"grad_rel_error_by_input", ok ? by_input : nlohmann::json(nullptr)},
         {"forward_per_iteration_ms", NumberOrNull(ok, r.forward_per_iteration_ms)},
         {"factorization_s", NumberOrNull(ok, r.factorization_s)},
         {"speedup_vs_newton_cholesky",
          r.speedup_vs_newton_cholesky ? nlohmann::json(*r.speedup_vs_newton_cholesky) : nlohmann::json(nullptr)},
         {"speedup_vs_best_newton",
          r.speedup_vs_best_newton ? nlohmann::json(*r.speedup_vs_best_newton) : nlohmann::json(nullptr)},
         {"speedup_vs_newton_ldlt",
          r.speedup_vs_newton_ldlt ? nlohmann::json(*r.speedup_vs_newton_ldlt) : nlohmann::json(nullptr)},
         {"backward_iterative_steps", ok ? nlohmann::json(r.backward_iterative_steps) : nlohmann::json(nullptr)},
         {"backward_direct_steps", ok ? nlohmann::json(r.backward_direct_steps) : nlohmann::json(nullptr)},
         {"adjoint_solver", ToString(options.adjoint_solver)},
         {"problem", result.problem},
         {"dofs", result.dofs},
         {"elements", result.elements},
         {"steps", result.steps},
         {"time_step", result.time_step},
         {"rel_tolerance", options.rel_tolerance},
         {"threads", options.threads},
         {"repeat", options.repeat}});
  }
  return rows;
}

ScalingResult RunScaling(const std::string& problem, const BenchOptions& options, const std::vector<int>& factors,
                         std::ostream* progress) {
  options.Validate();
  if (factors.empty()) throw InvalidInputError("scales is empty: give at least one element-count factor");
  ScalingResult result;
  for (int f : factors) {
    if (f < 1 || (f & (f - 1)) != 0) {
      std::ostringstream msg;
      msg << "scale = " << f << " is invalid: must be a power of 2 (1, 2, 4, 8, ...)";
      throw InvalidInputError(msg.str());
    }
  }
  for (int f : factors) {
    int doublings = 0;
    while ((1 << doublings) < f) ++doublings;
    const Setup s = MakeSetup(problem, options.refine + doublings, options);
    {
      std::ostringstream line;
      line << "[scaling] " << f << "x: " << s.scene.mesh.num_elements() << " elements, " << s.scene.mesh.num_dofs()
           << " DoFs";
      Progress(progress, line.str());
    }
    for (Method method : options.methods) {
      const RolloutMeasurement m = MeasureRollout(s.scene, MethodOptions(method, options, s.time_step), s.initial,
                                                  s.inputs, s.loss, options.repeat);
      Progress(progress, std::string("[scaling] ") + std::to_string(f) + "x " + ToString(method) + ": " + Describe(m));
      ScalingRow row;
      row.method = ToString(method);
      row.factor = f;
      row.elements = s.scene.mesh.num_elements();
      row.vertices = s.scene.mesh.num_vertices();
      row.dofs = s.scene.mesh.num_dofs();
      row.failure = m.failure;
      if (m.ok()) {
        row.forward_s = m.forward_s;
        row.backward_s = m.backward_s;
        row.iters_per_step = m.iters_per_step;
        row.forward_per_iteration_ms = m.total_iterations > 0 ? 1e3 * m.forward_s / m.total_iterations : 0;
        row.factorization_s = m.factorization_s;
        row.iteration_ms = m.total_iterations > 0 ? 1e3 * (m.forward_s - m.factorization_s) / m.total_iterations : 0;
        row.backward_per_step_ms = 1e3 * m.backward_s / s.steps;
        row.backward_direct_steps = m.backward_direct_steps;
        row.factor_copy_mib = m.factor_copy_bytes / 1048576.0;
      }
      row.peak_rss_mib = PeakRssMib();
      result.rows.push_back(row);
    }
  }
  // Least-squares slope of log(ms) against log(DoFs) over a method's rows.
  auto fit_exponent = [&](Method method, double ScalingRow::*ms, std::map<std::string, double>* out) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int k = 0;
    for (const auto& r : result.rows) {
      if (r.method != ToString(method) || !r.failure.empty() || r.*ms <= 0) continue;
      const double x = std::log(double(r.dofs)), y = std::log(r.*ms);
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++k;
    }
    const double det = k * sxx - sx * sx;
    if (k >= 2 && det > 0) (*out)[ToString(method)] = (k * sxy - sx * sy) / det;
  };
  for (Method method : options.methods) {
    fit_exponent(method, &ScalingRow::iteration_ms, &result.exponent_per_iteration);
    fit_exponent(method, &ScalingRow::forward_per_iteration_ms, &result.exponent_with_factorization);
  }
  return result;
}

nlohmann::json ScalingToJson(const ScalingResult& result) {
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& r : result.rows) {
    const bool ok = r.failure.empty();
    const auto exponent = result.exponent_per_iteration.find(r.method);
    const auto with_factorization = result.exponent_with_factorization.find(r.method);
    rows.push_back(
        {{"method", r.method},
         {"status", ok ? std::string("ok") : "failed: " + r.failure},
         {"factor", r.factor},
         {"elements", r.elements},
         {"vertices", r.vertices},
         {"dofs", r.dofs},
         {"forward_s", NumberOrNull(ok, r.forward_s)},
         {"backward_s", NumberOrNull(ok, r.backward_s)},
         {"iters_per_step", NumberOrNull(ok, r.iters_per_step)},
         {"forward_per_iteration_ms", NumberOrNull(ok, r.forward_per_iteration_ms)},
         {"factorization_s", NumberOrNull(ok, r.factorization_s)},
         {"iteration_ms", NumberOrNull(ok, r.iteration_ms)},
         {"backward_per_step_ms", NumberOrNull(ok, r.backward_per_step_ms)},
         {"backward_direct_steps", ok ? nlohmann::json(r.backward_direct_steps) : nlohmann::json(nullptr)},
         {"factor_copy_mib", NumberOrNull(ok, r.factor_copy_mib)},
         {"peak_rss_mib", r.peak_rss_mib},
         {"exponent_per_iteration",
          exponent == result.exponent_per_iteration.end() ? nlohmann::json(nullptr) : nlohmann::json(exponent->second)},
         {"exponent_with_factorization", with_factorization == result.exponent_with_factorization.end()
                                             ? nlohmann::json(nullptr)
                                             : nlohmann::json(with_factorization->second)}});
  }
  return rows;
}

std::vector<ThreadsRow> RunThreadsCompare(const std::string& problem, const BenchOptions& options,
                                          int energy_evaluations, std::ostream* progress) {
  options.Validate();
  if (energy_evaluations < 1) {
    std::ostringstream msg;
    msg << "energy_evaluations = " << energy_evaluations << " is invalid: must be >= 1";
    throw InvalidInputError(msg.str());
  }
  const Setup s = MakeSetup(problem, options.refine, options);
  std::vector<ThreadsRow> rows;
  for (Method method : options.methods) {
    ThreadsRow row;
    row.method = ToString(method);
    for (int threads : {1, 2}) {
      BenchOptions o = options;
      o.threads = threads;
      const SolverOptions so = MethodOptions(method, o, s.time_step);
      const RolloutMeasurement m = MeasureRollout(s.scene, so, s.initial, s.inputs, s.loss, options.repeat);
      Progress(progress, "[threads] " + row.method + " with " + std::to_string(threads) + " thread(s): " + Describe(m));
      if (!m.ok()) {
        row.failure = m.failure;
        break;
      }
      // Alternates between the last two states (x_K and x_{K-1} = x_K - h v_K)
      // so that the SVDs' warm start is a step old, as in a solve; repeating
      // one x would let every SVD stop after its first check.
      Simulator sim(s.scene, so);
      const VectorXd x_last = m.final_state.x;
      const VectorXd x_before = x_last - s.time_step * m.final_state.v;
      sim.ElasticEnergy(x_before);  // warm-up
      const auto start = Clock::now();
      double sink = 0;
      for (int k = 0; k < energy_evaluations; ++k) sink += sim.ElasticEnergy(k % 2 ? x_before : x_last);
      const double local_ms = 1e3 * SecondsSince(start) / energy_evaluations;
      if (!std::isfinite(sink)) row.failure = "non-finite elastic energy";
      (threads == 1 ? row.step_s_1 : row.step_s_2) = m.forward_s / s.steps;
      (threads == 1 ? row.backward_s_1 : row.backward_s_2) = m.backward_s;
      (threads == 1 ? row.local_ms_1 : row.local_ms_2) = local_ms;
    }
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json ThreadsToJson(const std::vector<ThreadsRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows) {
    const bool ok = r.failure.empty();
    out.push_back({{"method", r.method},
                   {"status", ok ? std::string("ok") : "failed: " + r.failure},
                   {"step_s_1_thread", NumberOrNull(ok, r.step_s_1)},
                   {"step_s_2_threads", NumberOrNull(ok, r.step_s_2)},
                   {"step_speedup", NumberOrNull(ok, r.step_speedup())},
                   {"backward_s_1_thread", NumberOrNull(ok, r.backward_s_1)},
                   {"backward_s_2_threads", NumberOrNull(ok, r.backward_s_2)},
                   {"backward_speedup", NumberOrNull(ok, r.backward_speedup())},
                   {"local_step_ms_1_thread", NumberOrNull(ok, r.local_ms_1)},
                   {"local_step_ms_2_threads", NumberOrNull(ok, r.local_ms_2)},
                   {"local_step_speedup", NumberOrNull(ok, r.local_speedup())}});
  }
  return out;
}

}  // namespace diffpd::problems
