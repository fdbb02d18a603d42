#include "tools/tradeoff.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include "tools/bench.h"
#include "tools/problem_objective.h"
#include "tools/reference_cache.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "cli/invalid_option.h"

namespace diffpd::problems {
namespace {

void Progress(std::ostream* out, const std::string& line) {
  if (out) *out << line << std::endl;
}

RolloutMeasurement MustSucceed(RolloutMeasurement m, const std::string& what) {
  if (!m.ok())
    throw SolverError(m.status,
                      "the reference (" + what + ", newton-cholesky, rel_tolerance 1e-10) failed: " + m.failure);
  return m;
}

TradeoffRow MakeRow(const std::string& sweep, Method method, const std::string& parameter, double value,
                    const RolloutMeasurement& m, int dofs, int steps) {
  TradeoffRow row;
  row.sweep = sweep;
  row.method = ToString(method);
  row.parameter = parameter;
  row.value = value;
  row.failure = m.failure;
  row.dofs = dofs;
  row.steps = steps;
  if (m.ok()) {
    row.forward_s = m.forward_s;
    row.backward_s = m.backward_s;
    row.seconds = m.forward_s + m.backward_s;
    row.iters_per_step = m.iters_per_step;
  }
  return row;
}

std::string Describe(const TradeoffRow& r) {
  std::ostringstream s;
  s << "[tradeoff] " << r.sweep << " " << r.method << " " << r.parameter << " = "
    << (r.setting.empty() ? std::to_string(r.value) : r.setting) << ": ";
  if (!r.failure.empty())
    s << "failed: " << r.failure;
  else
    s << r.seconds << " s, state error " << r.state_rel_error << ", loss error " << r.loss_rel_error
      << ", gradient error " << r.grad_rel_error;
  return s.str();
}

// The DoFs of the 8 nodes nearest the corners of the rest bounding box.
std::vector<int> CornerDofs(const Mesh& mesh) {
  const Vec3 lo = mesh.vertices.rowwise().minCoeff(), hi = mesh.vertices.rowwise().maxCoeff();
  std::vector<int> dofs;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    Eigen::Index best;
    (mesh.vertices.colwise() - corner).colwise().squaredNorm().minCoeff(&best);
    for (int d = 0; d < 3; ++d) dofs.push_back(3 * static_cast<int>(best) + d);
  }
  return dofs;
}

// A resolution level's corner displacements and scaled material gradient.
struct CornerMeasurement {
  RolloutMeasurement m;
  VectorXd displacement;       // 24
  VectorXd material_gradient;  // (E dL/dE, nu dL/dnu, rho dL/drho)
  int dofs = 0, steps = 0, elements = 0;
  bool ok() const { return m.ok(); }
};

double SecondsOf(const RolloutMeasurement& m) { return m.forward_s + m.backward_s; }
double SecondsOf(const ObjectiveMeasurement& m) { return m.forward_s + m.backward_s; }
double SecondsOf(const CornerMeasurement& c) { return SecondsOf(c.m); }

double ProcessCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

template <typename M>
struct Timed {
  M m;
  double cpu_s = 0;    // process CPU seconds of the call
  double seconds = 0;  // what the row reports: SecondsOf(m) or cpu_s
};

// The fastest successful one of `repeats` runs of `measure` on `clock` (the
// first when it fails).
template <typename Measure>
auto Fastest(int repeats, TradeoffClock clock, Measure measure) {
  auto once = [&] {
    const double start = ProcessCpuSeconds();
    Timed<decltype(measure())> t{measure()};
    t.cpu_s = ProcessCpuSeconds() - start;
    t.seconds = clock == TradeoffClock::kCpu ? t.cpu_s : SecondsOf(t.m);
    return t;
  };
  auto best = once();
  for (int k = 1; k < repeats && best.m.ok(); ++k) {
    auto again = once();
    if (again.m.ok() && again.seconds < best.seconds) best = std::move(again);
  }
  return best;
}

// Sets a successful row's times from its timed measurement.
template <typename M>
void SetTimes(const Timed<M>& t, TradeoffRow* row) {
  if (!row->ok()) return;
  row->cpu_s = t.cpu_s;
  row->seconds = t.seconds;
}

CornerMeasurement MeasureCorners(const std::string& problem_name, int doublings, const SolverOptions& so,
                                 int steps_option, const VectorXd& corner_weights) {
  const auto problem = MakeRefinedProblem(problem_name, doublings);
  const Scene scene = problem->MakeScene();
  const int steps = steps_option > 0 ? steps_option : problem->default_steps();
  Simulator sim(scene, so);
  const State initial = problem->InitialState(sim);
  const std::vector<int> corners = CornerDofs(scene.mesh);
  LinearLoss loss;
  loss.cx = VectorXd::Zero(sim.num_dofs());
  loss.cv = VectorXd::Zero(sim.num_dofs());
  for (size_t k = 0; k < corners.size(); ++k) loss.cx(corners[k]) = corner_weights(k);
  CornerMeasurement out;
  out.m = MeasureRollout(scene, so, initial, problem->Inputs(sim, steps), loss, 1);
  out.dofs = sim.num_dofs();
  out.steps = steps;
  out.elements = scene.mesh.num_elements();
  if (out.m.ok()) {
    const VectorXd rest = sim.RestState().x;
    out.displacement.resize(corners.size());
    for (size_t k = 0; k < corners.size(); ++k)
      out.displacement(k) = out.m.final_state.x(corners[k]) - rest(corners[k]);
    const int n = sim.num_dofs();
    const MaterialParameters& mat = scene.material;
    out.material_gradient =
        Eigen::Vector3d(mat.youngs_modulus * out.m.gradient(2 * n), mat.poissons_ratio * out.m.gradient(2 * n + 1),
                        mat.density * out.m.gradient(2 * n + 2));
  }
  return out;
}

// Options of a method at a tolerance on top of the problem's settings.
SolverOptions SweepOptions(const SolverOptions& defaults, Method method, double tolerance, double h) {
  SolverOptions s = defaults;
  s.method = method;
  s.time_step = h;
  s.rel_tolerance = tolerance;
  if (defaults.backward_rel_tolerance == defaults.rel_tolerance) s.backward_rel_tolerance = tolerance;
  return s;
}

SolverOptions ConvergedOptions(const SolverOptions& defaults, double h) {
  SolverOptions s = SweepOptions(defaults, Method::kNewtonCholesky, kReferenceRelTolerance, h);
  s.backward_rel_tolerance = kReferenceBackwardRelTolerance;
  s.tolerance_reference = ToleranceReference::kStartResidual;
  return s;
}

void RunTimeStepSweep(const std::string& problem_name, const TradeoffOptions& o, const SolverOptions& defaults,
                      double tolerance, std::ostream* progress, std::vector<TradeoffRow>* rows) {
  const auto problem = MakeRefinedProblem(problem_name, o.instance.refine);
  const Scene scene = problem->MakeScene();
  const int steps = o.instance.steps > 0 ? o.instance.steps : problem->default_steps();
  const double h0 = defaults.time_step;
  State initial;
  LinearLoss loss;
  {
    Simulator sim(scene, ConvergedOptions(defaults, h0));
    initial = problem->InitialState(sim);
    loss = LinearLoss::Random(sim.num_dofs(), o.seed);
  }
  auto inputs_for = [&](double h, int k) {
    Simulator sim(scene, ConvergedOptions(defaults, h));
    return problem->Inputs(sim, k);
  };
  const int dofs = scene.mesh.num_dofs();
  const int ref_steps = steps << o.time_step_levels;
  const double ref_h = h0 / (1 << o.time_step_levels);
  std::ostringstream key;
  key.precision(17);
  key << "tradeoff time-step reference v1|" << problem_name << "|steps " << ref_steps << "|h " << ref_h << "|refine "
      << o.instance.refine << "|seed " << o.seed << "|max_iterations " << o.max_iterations;
  const ReferenceValues ref = CachedReference(o.cache_dir, problem_name, key.str(), [&] {
    Progress(progress, "[tradeoff] time-step sweep: reference at h = " + std::to_string(ref_h) + " s (" +
                           std::to_string(ref_steps) + " steps) ...");
    const RolloutMeasurement m = MustSucceed(
        MeasureRollout(scene, ConvergedOptions(defaults, ref_h), initial, inputs_for(ref_h, ref_steps), loss),
        "time-step sweep");
    ReferenceValues r;
    r.loss = loss.Value(m.final_state);
    r.state = StackState(m.final_state);
    r.gradient = m.gradient;
    r.seconds = m.forward_s + m.backward_s;
    return r;
  });
  for (Method method : o.methods)
    for (int k = 0; k < o.time_step_levels; ++k) {
      const double h = h0 / (1 << k);
      const int n_steps = steps << k;
      const SolverOptions so = SweepOptions(defaults, method, tolerance, h);
      const auto timed =
          Fastest(o.repeats, o.clock, [&] { return MeasureRollout(scene, so, initial, inputs_for(h, n_steps), loss); });
      const RolloutMeasurement& m = timed.m;
      TradeoffRow row = MakeRow("time_step", method, "time_step", h, m, dofs, n_steps);
      SetTimes(timed, &row);
      row.rel_tolerance = tolerance;
      if (m.ok()) {
        row.state_rel_error = RelativeError(StackState(m.final_state), ref.state);
        row.loss_rel_error =
            RelativeError(VectorXd::Constant(1, loss.Value(m.final_state)), VectorXd::Constant(1, ref.loss));
        row.grad_rel_error = RelativeError(m.gradient, ref.gradient);
      }
      Progress(progress, Describe(row));
      rows->push_back(row);
    }
}

void RunResolutionSweep(const std::string& problem_name, const TradeoffOptions& o, double h0, double tolerance,
                        std::ostream* progress, std::vector<TradeoffRow>* rows) {
  SolverOptions defaults;
  defaults.num_threads = o.threads;
  defaults.max_iterations = o.max_iterations > 0 ? o.max_iterations : 1000;
  const VectorXd corner_weights = LinearLoss::Random(24, o.seed + 1).cx;  // one per corner DoF
  Progress(progress, "[tradeoff] resolution sweep: reference on the finest mesh ...");
  const CornerMeasurement ref =
      MeasureCorners(problem_name, o.instance.refine, ConvergedOptions(defaults, h0), o.instance.steps, corner_weights);
  MustSucceed(ref.m, "resolution sweep");
  for (Method method : o.methods)
    for (int j = o.resolution_levels - 1; j >= 0; --j) {
      const SolverOptions so = SweepOptions(defaults, method, tolerance, h0);
      const auto timed = Fastest(o.repeats, o.clock, [&] {
        return MeasureCorners(problem_name, o.instance.refine - 3 * j, so, o.instance.steps, corner_weights);
      });
      const CornerMeasurement& c = timed.m;
      TradeoffRow row = MakeRow("resolution", method, "elements", c.elements, c.m, c.dofs, c.steps);
      SetTimes(timed, &row);
      row.rel_tolerance = tolerance;
      if (c.m.ok()) {
        row.state_rel_error = RelativeError(c.displacement, ref.displacement);
        row.grad_rel_error = RelativeError(c.material_gradient, ref.material_gradient);
      }
      Progress(progress, Describe(row));
      rows->push_back(row);
    }
}

}  // namespace

void TradeoffOptions::Validate() const {
  const auto fail = ThrowInvalidOption;
  if (methods.empty()) throw InvalidInputError("methods is empty: name at least one method");
  for (Method m : methods)
    if (m == Method::kSemiImplicit)
      throw InvalidInputError(
          "method semi-implicit has no tolerance to trade: use newton-cholesky, newton-pcg, "
          "pd or pd-lbfgs");
  if (sweep_tolerance && tolerances.empty()) throw InvalidInputError("tolerances is empty: give at least one");
  for (double t : tolerances)
    if (!(t > 0 && t < 1)) fail("tolerance", t, "in (0, 1)");
  if (!(rel_tolerance < 1) || std::isnan(rel_tolerance)) fail("rtol", rel_tolerance, "< 1 (<= 0: the problem's)");
  for (double f : backward_factors)
    if (!(f > 0 && f <= 1)) fail("backward factor", f, "in (0, 1]");
  for (double r : screenings)
    if (!(r >= 0 && r < 1)) fail("screening", r, "in [0, 1)");
  if (threads < 0 || threads > MaxSolverThreads()) fail("threads", threads, ThreadRange());
  if (max_iterations < 1 && max_iterations != -1) fail("max iterations", max_iterations, ">= 1 (or -1: the problem's)");
  if (repeats < 1) fail("repeats", repeats, ">= 1");
  if (time_step_levels < 1) fail("time-step levels", time_step_levels, ">= 1");
  if (resolution_levels < 1) fail("resolution levels", resolution_levels, ">= 1");
  if (!std::isfinite(time_step)) fail("dt", time_step, "finite (> 0, or <= 0 for the default)");
}

namespace {

VectorXd ToVector(double v) { return VectorXd::Constant(1, v); }

TradeoffRow ObjectiveRow(const std::string& sweep, const SolverOptions& so, const std::string& parameter, double value,
                         const std::string& setting, const ObjectiveMeasurement& m, const ReferenceValues& ref,
                         const ProblemObjective& objective) {
  TradeoffRow row;
  row.sweep = sweep;
  row.method = ToString(so.method);
  row.parameter = parameter;
  row.value = value;
  row.setting = setting;
  row.rel_tolerance = so.rel_tolerance;
  row.failure = m.failure;
  row.dofs = objective.dofs;
  row.steps = objective.steps;
  if (m.ok()) {
    row.forward_s = m.forward_s;
    row.backward_s = m.backward_s;
    row.seconds = m.forward_s + m.backward_s;
    row.iters_per_step = m.iters_per_step;
    row.state_rel_error = RelativeError(m.final_state, ref.state);
    row.loss_rel_error = RelativeError(ToVector(m.loss), ToVector(ref.loss));
    row.grad_rel_error = RelativeError(m.gradient, ref.gradient);
  }
  return row;
}

// Whether a run with `a` computes what one with `b` does (what the
// tradeoff sweeps vary).
bool SameSettings(const SolverOptions& a, const SolverOptions& b) {
  return a.method == b.method && a.rel_tolerance == b.rel_tolerance && a.abs_tolerance == b.abs_tolerance &&
         a.max_iterations == b.max_iterations && a.backward_rel_tolerance == b.backward_rel_tolerance &&
         a.backward_tolerance_factor == b.backward_tolerance_factor && a.adjoint_solver == b.adjoint_solver &&
         a.tolerance_reference == b.tolerance_reference && a.time_step == b.time_step;
}

std::string ReferenceKey(const std::string& what, const ProblemObjective& objective, const TradeoffOptions& o) {
  std::ostringstream key;
  key.precision(17);
  key << "tradeoff reference v3|" << what << "|" << objective.problem << "|masses " << objective.masses << "|steps "
      << objective.steps << "|dofs " << objective.dofs << "|h " << objective.defaults.time_step << "|refine "
      << o.instance.refine << "|max_iterations " << o.max_iterations << "|seed " << o.seed << "|rtol "
      << kReferenceRelTolerance << "|btol " << kReferenceBackwardRelTolerance << "|max_energy_gain "
      << kReferenceMaxEnergyGain;
  return key.str();
}

}  // namespace

TradeoffResult RunTradeoff(const std::string& problem_name, const TradeoffOptions& o, std::ostream* progress) {
  o.Validate();
  TradeoffResult result;
  const ProblemObjective objective = MakeProblemObjective(problem_name, o.threads, o.instance);
  if (o.time_step > 0 && !objective.time_step_knob)
    throw InvalidInputError("--dt is invalid for " + problem_name + ": the problem fixes its time step");
  Progress(progress, "[tradeoff] " + problem_name + ": " + std::to_string(objective.dofs) + " DoFs, " +
                         std::to_string(objective.steps) + " steps" +
                         (objective.masses.empty() ? "" : ", " + objective.masses + " masses") + ", gradient w.r.t. " +
                         objective.variables);
  SolverOptions defaults = objective.defaults;
  defaults.num_threads = o.threads;
  if (o.max_iterations > 0) defaults.max_iterations = o.max_iterations;
  if (o.time_step > 0) defaults.time_step = o.time_step;
  const bool tied_backward = defaults.backward_rel_tolerance == defaults.rel_tolerance;
  result.problem = problem_name;
  result.variables = objective.variables;
  result.loss = objective.loss;
  result.dofs = objective.dofs;
  result.steps = objective.steps;
  result.time_step = defaults.time_step;
  result.masses = objective.masses;
  result.default_method = ToString(defaults.method);
  result.default_rel_tolerance = defaults.rel_tolerance;
  result.repeats = o.repeats;
  result.clock = o.clock;

  // The converged reference of the problem's own loss.
  ProblemObjective keyed = objective;
  keyed.defaults = defaults;
  const ReferenceValues ref = CachedReference(
      o.cache_dir, problem_name, ReferenceKey("objective", keyed, o),
      [&] {
        Progress(progress, "[tradeoff] reference (newton-cholesky, rel_tolerance 1e-10) ...");
        SolverOptions so = defaults;
        so.method = Method::kNewtonCholesky;
        so.rel_tolerance = kReferenceRelTolerance;
        so.backward_rel_tolerance = kReferenceBackwardRelTolerance;
        so.tolerance_reference = ToleranceReference::kStartResidual;
        so.abs_tolerance = std::min(so.abs_tolerance, 1e-10);
        so.max_iterations = std::max(so.max_iterations, 1000);
        // No screening, and the contact energy guard relaxed: a step solved
        // to convergence has no solve slack left to hide a small energy gain
        // of its pinned nodes, which the guard would refuse where looser
        // solves pass; the guard changes no step it accepts.
        ContactOverrides contact;
        contact.screening_rel_tolerance = 0;
        contact.max_energy_gain = kReferenceMaxEnergyGain;
        const ObjectiveMeasurement m = objective.measure(so, contact);
        if (!m.ok())
          throw std::runtime_error("the reference of " + problem_name +
                                   " (newton-cholesky, rel_tolerance 1e-10) failed: " + m.failure);
        ReferenceValues r;
        r.loss = m.loss;
        r.gradient = m.gradient;
        r.state = m.final_state;
        r.seconds = m.forward_s + m.backward_s;
        return r;
      },
      &result.reference_cached);
  result.reference_s = ref.seconds;
  Progress(progress, std::string("[tradeoff] reference ") + (result.reference_cached ? "from the cache" : "computed") +
                         " (" + std::to_string(ref.seconds) + " s)");

  auto run = [&](const std::string& sweep, const SolverOptions& so, const std::string& parameter, double value,
                 const std::string& setting, double screening = -1) {
    ContactOverrides contact;
    contact.screening_rel_tolerance = screening;
    const auto timed = Fastest(o.repeats, o.clock, [&] { return objective.measure(so, contact); });
    TradeoffRow row = ObjectiveRow(sweep, so, parameter, value, setting, timed.m, ref, objective);
    SetTimes(timed, &row);
    // A screening run at the scene's own screening tolerance repeats the
    // default's settings.
    row.default_settings = SameSettings(so, defaults) && (screening < 0 || screening == objective.screening);
    Progress(progress, Describe(row));
    result.rows.push_back(row);
  };
  auto at_tolerance = [&](Method method, double tol) {
    SolverOptions so = defaults;
    so.method = method;
    so.rel_tolerance = tol;
    if (tied_backward) so.backward_rel_tolerance = tol;
    return so;
  };

  run("default", defaults, "rel_tolerance", defaults.rel_tolerance, "");
  if (o.sweep_tolerance)
    for (Method method : o.methods)
      for (double tol : o.tolerances) run("tolerance", at_tolerance(method, tol), "rel_tolerance", tol, "");

  if (o.sweep_solver_options) {
    const ToleranceReference other = defaults.tolerance_reference == ToleranceReference::kStartResidual
                                         ? ToleranceReference::kInertia
                                         : ToleranceReference::kStartResidual;
    const std::string other_name = other == ToleranceReference::kInertia ? "inertia" : "start_residual";
    for (double tol : o.tolerances) {
      SolverOptions so = at_tolerance(defaults.method, tol);
      so.tolerance_reference = other;
      run("tolerance_reference", so, "rel_tolerance", tol, other_name);
    }
    std::vector<Method> pd_methods;
    for (Method m : o.methods)
      if (m == Method::kPd || m == Method::kPdLbfgs) pd_methods.push_back(m);
    for (Method method : pd_methods)
      for (AdjointSolver a : {AdjointSolver::kAuto, AdjointSolver::kIterative, AdjointSolver::kDirect}) {
        SolverOptions so = at_tolerance(method, defaults.rel_tolerance);
        so.adjoint_solver = a;
        run("adjoint_solver", so, "adjoint_solver", static_cast<double>(a), ToString(a));
      }
    for (Method method : pd_methods)
      for (double factor : o.backward_factors) {
        SolverOptions so = at_tolerance(method, defaults.rel_tolerance);
        so.backward_rel_tolerance = 0;
        so.backward_tolerance_factor = factor;
        run("backward_tolerance", so, "backward_tolerance_factor", factor, "");
      }
    if (objective.frictional_contact && objective.screening_knob)
      for (double screening : o.screenings)
        run("screening", defaults, "screening_rel_tolerance", screening, "", screening);
  }

  const double sweep_tolerance = o.rel_tolerance > 0 ? o.rel_tolerance : defaults.rel_tolerance;
  if (o.sweep_time_step && objective.time_step_knob)
    RunTimeStepSweep(problem_name, o, defaults, sweep_tolerance, progress, &result.rows);
  if (o.sweep_resolution && objective.resolution_knob)
    RunResolutionSweep(problem_name, o, defaults.time_step, sweep_tolerance, progress, &result.rows);
  return result;
}

nlohmann::json TradeoffToJson(const std::vector<TradeoffRow>& rows) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& r : rows) {
    const bool ok = r.ok();
    auto num = [ok](double v) { return ok ? nlohmann::json(v) : nlohmann::json(nullptr); };
    out.push_back({{"sweep", r.sweep},
                   {"method", r.method},
                   {"parameter", r.parameter},
                   {"value", r.value},
                   {"setting", r.setting},
                   {"rel_tolerance", r.rel_tolerance},
                   {"seconds", num(r.seconds)},
                   {"state_rel_error", num(r.state_rel_error)},
                   {"loss_rel_error", num(r.loss_rel_error)},
                   {"grad_rel_error", num(r.grad_rel_error)},
                   {"status", ok ? std::string("ok") : "failed: " + r.failure},
                   {"forward_s", num(r.forward_s)},
                   {"backward_s", num(r.backward_s)},
                   {"cpu_s", num(r.cpu_s)},
                   {"default_settings", r.default_settings},
                   {"iters_per_step", num(r.iters_per_step)},
                   {"dofs", r.dofs},
                   {"steps", r.steps}});
  }
  return out;
}

std::vector<TradeoffRow> TradeoffRowsFromJson(const nlohmann::json& rows) {
  if (!rows.is_array()) throw InvalidInputError("the report's rows are invalid: must be a list");
  // TradeoffToJson's fields; a failed run's numbers are null (read as 0).
  static const std::pair<const char*, std::string TradeoffRow::*> kTexts[] = {{"sweep", &TradeoffRow::sweep},
                                                                              {"method", &TradeoffRow::method},
                                                                              {"parameter", &TradeoffRow::parameter},
                                                                              {"setting", &TradeoffRow::setting}};
  static const std::pair<const char*, double TradeoffRow::*> kNumbers[] = {
      {"value", &TradeoffRow::value},
      {"rel_tolerance", &TradeoffRow::rel_tolerance},
      {"seconds", &TradeoffRow::seconds},
      {"state_rel_error", &TradeoffRow::state_rel_error},
      {"loss_rel_error", &TradeoffRow::loss_rel_error},
      {"grad_rel_error", &TradeoffRow::grad_rel_error},
      {"forward_s", &TradeoffRow::forward_s},
      {"backward_s", &TradeoffRow::backward_s},
      {"cpu_s", &TradeoffRow::cpu_s},
      {"iters_per_step", &TradeoffRow::iters_per_step}};
  std::vector<TradeoffRow> out;
  for (size_t i = 0; i < rows.size(); ++i) {
    const nlohmann::json& j = rows[i];
    std::string field;
    try {
      TradeoffRow r;
      for (const auto& [key, member] : kTexts) r.*member = j.at(field = key).get<std::string>();
      for (const auto& [key, member] : kNumbers) {
        const nlohmann::json& v = j.at(field = key);
        r.*member = v.is_null() ? 0.0 : v.get<double>();
      }
      const std::string status = j.at(field = "status").get<std::string>();
      if (status.rfind("failed: ", 0) == 0) r.failure = status.substr(8);
      r.default_settings = j.at(field = "default_settings").get<bool>();
      r.dofs = j.at(field = "dofs").get<int>();
      r.steps = j.at(field = "steps").get<int>();
      out.push_back(r);
    } catch (const nlohmann::json::exception&) {
      throw InvalidInputError("the report's row " + std::to_string(i) + " is invalid: field '" + field +
                              "' is missing or has the wrong type");
    }
  }
  return out;
}

std::string GnuplotQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    if (c == '\n' || c == '\r') throw InvalidInputError("plot path contains a line break: give a plain file name");
    out += c;
    if (c == '\'') out += '\'';
  }
  return out + "'";
}

void RunGnuplot(const std::string& script, const std::string& png_path) {
  FILE* pipe = popen("gnuplot", "w");
  if (!pipe) throw std::runtime_error("could not start gnuplot");
  std::fwrite(script.data(), 1, script.size(), pipe);
  const int status = pclose(pipe);
  if (status != 0) {
    std::ostringstream msg;
    msg << "gnuplot failed (status " << status << ") while writing " << png_path;
    throw std::runtime_error(msg.str());
  }
  if (!std::filesystem::is_regular_file(png_path) || std::filesystem::file_size(png_path) == 0)
    throw std::runtime_error("gnuplot did not write " + png_path);
}

bool GnuplotAvailable() {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/gnuplot";
    if (std::filesystem::is_regular_file(candidate) && access(candidate.c_str(), X_OK) == 0) return true;
  }
  return false;
}

namespace {
// "adjoint_solver" -> "adjoint solver" (gnuplot's enhanced text makes _ a subscript).
std::string Spaced(std::string s) {
  std::replace(s.begin(), s.end(), '_', ' ');
  return s;
}
}  // namespace

void WriteTradeoffPlot(const std::vector<TradeoffRow>& rows, const std::string& png_path, const std::string& title,
                       TradeoffClock clock) {
  if (!GnuplotAvailable())
    throw std::runtime_error(
        "--plot needs the gnuplot program, which is not on PATH (Debian: apt-get install "
        "gnuplot-nox), or leave out --plot");
  // Columns: the runs at the problem's settings, then the time-step and
  // resolution sweeps where present.
  auto column_of = [](const TradeoffRow& r) { return r.at_problem_settings() ? std::string("settings") : r.sweep; };
  std::vector<std::string> present;
  for (const std::string c : {"settings", "time_step", "resolution"})
    for (const auto& r : rows)
      if (column_of(r) == c && r.ok()) {
        present.push_back(c);
        break;
      }
  if (present.empty()) throw std::runtime_error("nothing to plot: every tradeoff run failed");
  std::vector<std::string> methods;
  for (const auto& r : rows)
    if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
  const std::vector<std::string> options_sweeps = {"tolerance_reference", "adjoint_solver", "backward_tolerance",
                                                   "screening"};

  std::ostringstream script;
  script << "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) { set terminal pngcairo size " << 500 * present.size()
         << ",1200 } else { set terminal png size " << 500 * present.size() << ",1200 }\n";
  script << "set output " << GnuplotQuote(png_path) << "\n";
  script << "set logscale xy\nset format y '10^{%L}'\nset grid\nset key top right font ',8'\n";
  auto name = [](std::string n) {
    for (char& c : n)
      if (c == '-') c = '_';
    return "$" + n;
  };
  auto write_block = [&](const std::string& block, const std::function<bool(const TradeoffRow&)>& take) {
    script << name(block) << " << EOD\n";
    int n = 0;
    for (const auto& r : rows)
      if (r.ok() && take(r)) {
        script << r.seconds << " " << std::max(r.state_rel_error, 1e-17) << " " << std::max(r.loss_rel_error, 1e-17)
               << " " << std::max(r.grad_rel_error, 1e-17) << "\n";
        ++n;
      }
    script << "EOD\n";
    return n > 0;
  };
  // Blocks: (column, method) curves, the solver-option sweeps' points, the default.
  std::vector<std::pair<std::string, std::string>> curves;  // block, title
  std::map<std::string, std::vector<std::pair<std::string, std::string>>> by_column;
  for (const auto& c : present) {
    for (const auto& m : methods) {
      const std::string block = c + "_" + m;
      const std::string sweep = c == "settings" ? "tolerance" : c;
      if (write_block(block, [&](const TradeoffRow& r) { return r.sweep == sweep && r.method == m; }))
        by_column[c].push_back({block, m});
    }
    if (c == "settings") {
      for (const auto& sw : options_sweeps)
        if (write_block("opt_" + sw, [&](const TradeoffRow& r) { return r.sweep == sw; }))
          by_column[c].push_back({"opt_" + sw, Spaced(sw)});
      if (write_block("default_point", [](const TradeoffRow& r) { return r.sweep == "default"; }))
        by_column[c].push_back({"default_point", "default"});
    }
  }
  script << "set multiplot layout 3," << present.size() << " title " << GnuplotQuote(title) << "\n";
  const char* what[3] = {"final state", "loss", "gradient"};
  const char* time_label =
      clock == TradeoffClock::kCpu ? "CPU time of one evaluation (s)" : "forward + backward wall time (s)";
  for (int row = 0; row < 3; ++row)
    for (const auto& c : present) {
      const std::string label = c == "settings"    ? "method, tolerance and solver options"
                                : c == "time_step" ? "time-step sweep"
                                                   : "mesh-resolution sweep";
      script << "set title '" << label << "'\nset xlabel '" << time_label << "'\nset ylabel '" << what[row]
             << " relative error'\nplot ";
      bool first = true;
      for (const auto& [block, label_text] : by_column[c]) {
        const bool is_default = block == "default_point";
        const bool is_option = block.rfind("opt_", 0) == 0;
        script << (first ? "" : ", ") << name(block) << " using 1:" << (row + 2)
               << (is_default  ? " with points pt 3 ps 3 lw 2 lc rgb 'black'"
                   : is_option ? " with points ps 1.2"
                               : " with linespoints")
               << " title '" << label_text << "'";
        first = false;
      }
      script << "\n";
    }
  script << "unset multiplot\nset output\n";
  RunGnuplot(script.str(), png_path);
}

}  // namespace diffpd::problems
