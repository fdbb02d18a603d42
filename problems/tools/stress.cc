#include "tools/stress.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "tools/bench.h"
#include "tools/gradcheck.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "cli/invalid_option.h"

namespace diffpd::problems {
namespace {

using Clock = std::chrono::steady_clock;

std::string Describe(const SolverError& e) { return std::string(ToString(e.status())) + ": " + e.what(); }

bool GradientFinite(const RolloutGradient& g) {
  if (!g.x0.allFinite() || !g.v0.allFinite()) return false;
  for (const auto& f : g.external_force)
    if (!f.allFinite()) return false;
  return std::isfinite(g.youngs_modulus) && std::isfinite(g.poissons_ratio) && std::isfinite(g.density);
}

// Kinetic, elastic and gravitational (relative to the initial state) energy.
struct EnergyParts {
  double kinetic = 0, elastic = 0, gravity = 0;
  double total() const { return kinetic + elastic + gravity; }
  double magnitude() const { return std::abs(kinetic) + std::abs(elastic) + std::abs(gravity); }
};

}  // namespace

double AutoAbsTolerance(const Scene& scene, double time_step) {
  const Mesh& mesh = scene.mesh;
  const double rho = scene.material.density;
  // Node masses are not public here: spread the body's mass evenly (the
  // floor is an order of magnitude, not a bound).
  Eigen::Map<const Eigen::Matrix3Xd> x(mesh.vertices.data(), 3, mesh.num_vertices());
  const Vec3 lo = x.rowwise().minCoeff(), hi = x.rowwise().maxCoeff();
  const double volume = (hi - lo).prod();  // bounding box, m^3
  const double node_mass = rho * volume / mesh.num_vertices();
  const double element_area = std::pow(volume / mesh.num_elements(), 2.0 / 3.0);
  const double eps = std::numeric_limits<double>::epsilon();
  const double inertia = eps * node_mass * x.norm() / (time_step * time_step);
  const double modulus = 2 * scene.material.mu() + scene.material.lambda();  // P-wave modulus, Pa
  const double elastic = eps * modulus * element_area * std::sqrt(double(mesh.num_dofs()));
  return std::max(1e-9, 10 * (inertia + elastic));
}

void StressOptions::Validate() const {
  const auto fail = ThrowInvalidOption;
  if (problems.empty()) throw InvalidInputError("problems is empty: name at least one problem");
  if (methods.empty()) throw InvalidInputError("methods is empty: name at least one method");
  if (youngs_moduli.empty() || poissons_ratios.empty() || time_steps.empty())
    throw InvalidInputError("the grid is empty: give at least one Young's modulus, Poisson's ratio and time step");
  for (double e : youngs_moduli)
    if (!(std::isfinite(e) && e > 0)) fail("youngs_modulus", e, "finite and > 0 (Pa)");
  for (double nu : poissons_ratios)
    if (!(std::isfinite(nu) && nu > -1 && nu < 0.5)) fail("poissons_ratio", nu, "finite and in (-1, 0.5)");
  for (double h : time_steps)
    if (!(std::isfinite(h) && h > 0)) fail("time_step", h, "finite and > 0 (s)");
  if (steps < 1) fail("steps", steps, ">= 1");
  if (!(rel_tolerance > 0 && rel_tolerance < 1)) fail("rtol", rel_tolerance, "in (0, 1)");
  if (threads < 0 || threads > MaxSolverThreads()) fail("threads", threads, ThreadRange());
  if (max_iterations < 1) fail("max_iterations", max_iterations, ">= 1");
  if (!(energy_tolerance >= 0)) fail("energy_tolerance", energy_tolerance, ">= 0");
  if (!(explicit_energy_tolerance >= 0)) fail("explicit_energy_tolerance", explicit_energy_tolerance, ">= 0");
  if (!(contact_energy_tolerance >= 0)) fail("contact_energy_tolerance", contact_energy_tolerance, ">= 0");
  if (long_steps < 0) fail("long_steps", long_steps, ">= 0 (0: no long cases)");
  if (long_only && long_steps == 0) throw InvalidInputError("long_only is set without long cases: give long_steps > 0");
  if (gradcheck_steps < 0) fail("gradcheck_steps", gradcheck_steps, ">= 0");
  if (!(gradcheck_tolerance > 0)) fail("gradcheck_tolerance", gradcheck_tolerance, "> 0");
  if (!(gradcheck_rel_tolerance > 0 && gradcheck_rel_tolerance < 1))
    fail("gradcheck_rel_tolerance", gradcheck_rel_tolerance, "in (0, 1)");
}

StressCase RunStressCase(const StressProblem& problem, Method method, double youngs_modulus, double poissons_ratio,
                         double time_step, const StressOptions& options, std::ostream* progress, int steps) {
  StressCase c;
  c.long_case = steps > 0;
  c.steps = steps > 0 ? steps : options.steps;
  c.problem = problem.name;
  c.method = ToString(method);
  c.youngs_modulus = youngs_modulus;
  c.poissons_ratio = poissons_ratio;
  c.time_step = time_step;
  const auto start = Clock::now();
  auto finish = [&](const std::string& outcome, const std::string& message) {
    c.outcome = outcome;
    c.message = message;
    c.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return c;
  };
  try {
    const auto p = MakeRefinedProblem(problem.name, problem.refine);
    Scene scene = p->MakeScene();
    scene.material.youngs_modulus = youngs_modulus;
    scene.material.poissons_ratio = poissons_ratio;
    SolverOptions so;
    so.method = method;
    so.time_step = time_step;
    so.rel_tolerance = options.rel_tolerance;
    so.abs_tolerance = options.abs_tolerance > 0 ? options.abs_tolerance : AutoAbsTolerance(scene, time_step);
    so.num_threads = options.threads;
    so.max_iterations = options.max_iterations;
    so.rigid_mode_correction = options.rigid_mode_correction;
    Simulator sim(scene, so);
    steps = c.steps;
    const bool contact = !scene.frictional_contacts.empty();
    const VectorXd mass = sim.LumpedMass();
    VectorXd gravity = VectorXd::Zero(sim.num_dofs());
    if (scene.gravity)
      for (int i = 0; i < sim.num_dofs() / 3; ++i) gravity.segment<3>(3 * i) = *scene.gravity;

    Rollout rollout;
    rollout.material = scene.material;
    for (const MaterialRegion& region : scene.material_regions) rollout.region_materials.push_back(region.material);
    rollout.options = so;
    rollout.inputs = p->Inputs(sim, steps);
    rollout.reports.resize(steps);
    rollout.states.reserve(steps + 1);
    rollout.states.push_back(p->InitialState(sim));
    const State& initial = rollout.states.front();
    auto energy = [&](const State& s) {
      EnergyParts e;
      e.kinetic = 0.5 * s.v.cwiseProduct(mass).dot(s.v);
      e.elastic = sim.ElasticEnergy(s.x);
      e.gravity = -(s.x - initial.x).cwiseProduct(mass).dot(gravity);
      return e;
    };
    const EnergyParts e0 = energy(initial);
    auto last_report = Clock::now();
    for (int k = 0; k < steps; ++k) {
      State next;
      try {
        next = sim.Step(rollout.states.back(), rollout.inputs[k], &rollout.reports[k]);
      } catch (const SolverError& e) {
        std::ostringstream msg;
        msg << Describe(e) << " (step " << k + 1 << " of " << steps << ")";
        return finish("failed", msg.str());
      }
      if (!next.x.allFinite() || !next.v.allFinite()) {
        std::ostringstream msg;
        msg << "step " << k + 1 << " returned a non-finite state without an error";
        return finish("violation", msg.str());
      }
      EnergyParts e;
      try {
        e = energy(next);
      } catch (const SolverError& error) {
        std::ostringstream msg;
        msg << Describe(error) << " (energy after step " << k + 1 << " of " << steps << ")";
        return finish("failed", msg.str());
      }
      if (!std::isfinite(e.total())) {
        std::ostringstream msg;
        msg << "step " << k + 1 << " returned a state of non-finite energy without an error";
        return finish("violation", msg.str());
      }
      const double excess = (e.total() - e0.total()) / (e0.magnitude() + e.magnitude() + 1e-300);
      c.max_energy_excess = std::max(c.max_energy_excess, excess);
      rollout.states.push_back(std::move(next));
      c.steps_completed = k + 1;
      c.rounding_floor_steps += rollout.reports[k].rounding_floor_stop;
      c.newton_fallback_steps += rollout.reports[k].newton_fallback;
      const int in_contact = static_cast<int>(rollout.reports[k].contact_nodes.size());
      c.contact_steps += in_contact > 0;
      c.max_contact_nodes = std::max(c.max_contact_nodes, in_contact);
      if (progress && std::chrono::duration<double>(Clock::now() - last_report).count() > 10) {
        last_report = Clock::now();
        *progress << "  ... step " << k + 1 << " of " << steps << std::endl;
      }
    }
    const double energy_tolerance = method == Method::kSemiImplicit ? options.explicit_energy_tolerance
                                    : contact                       ? options.contact_energy_tolerance
                                                                    : options.energy_tolerance;
    if (c.max_energy_excess > energy_tolerance) {
      std::ostringstream msg;
      msg << "the total energy rose by " << c.max_energy_excess << " (relative) > energy tolerance " << energy_tolerance
          << " without an error";
      if (method == Method::kSemiImplicit) msg << " (semi-implicit: h above its stability limit)";
      return finish("violation", msg.str());
    }

    const LinearLoss loss = LinearLoss::Random(sim.num_dofs(), options.seed);
    LossGradient dl(steps);
    dl.dx[steps] = loss.cx;
    dl.dv[steps] = loss.cv;
    try {
      const RolloutGradient g = sim.Backward(rollout, dl);
      if (!GradientFinite(g)) return finish("violation", "the backward pass returned a non-finite gradient");
    } catch (const SolverError& e) {
      return finish("failed", "backward pass: " + Describe(e));
    }

    // The check's steps: the first ones, or a long case's last ones (from
    // the state the rollout reached there).
    const int prefix = std::min(options.gradcheck_steps, steps);
    const State& check_start = c.long_case ? rollout.states[steps - prefix] : initial;
    if (prefix > 0) {
      SolverOptions tight = so;
      tight.rel_tolerance = options.gradcheck_rel_tolerance;
      tight.backward_rel_tolerance = std::min(1e-12, options.gradcheck_rel_tolerance);
      tight.max_iterations = std::max(so.max_iterations, 20000);
      tight.abs_tolerance = AutoAbsTolerance(scene, time_step);
      GradCheckOptions gc;
      gc.directions = 1;
      gc.tolerance = options.gradcheck_tolerance;
      gc.seed = options.seed;
      GradCheckResult check;
      try {
        check = CheckRolloutGradient(scene, tight, check_start, prefix, gc);
      } catch (const SolverError& e) {
        std::ostringstream msg;
        msg << "gradient check (solves at rel_tolerance " << options.gradcheck_rel_tolerance << "): " << Describe(e);
        return finish("failed", msg.str());
      }
      c.gradcheck_run = true;
      c.gradcheck_reference = check.reference;
      c.gradcheck_reference_failure = check.reference_failure;
      if (progress && !check.reference_failure.empty())
        *progress << "  gradient check: the Newton-Cholesky reference is not compared: " << check.reference_failure
                  << std::endl;
      c.gradcheck_margin = std::numeric_limits<double>::infinity();
      for (const auto& input : check.inputs) {
        if (input.verdict == CheckVerdict::kUnresolved) {
          c.gradcheck_unresolved.push_back(input.input);
          if (progress)
            *progress << "  gradient check: " << input.input << " unresolved: " << input.reason << std::endl;
          continue;
        }
        const bool by_tangent = input.basis == "tangent";
        if (by_tangent) c.gradcheck_tangent.push_back(input.input);
        if (input.verdict == CheckVerdict::kPass && !std::isnan(input.tightened_reference_error))
          c.gradcheck_tightened.push_back(input.input);
        c.gradcheck_error = std::max(c.gradcheck_error, by_tangent ? input.tangent_error : input.error);
        c.gradcheck_floor = std::max(c.gradcheck_floor, input.floor);
        c.gradcheck_margin = std::min(c.gradcheck_margin, input.margin);
      }
      if (check.verdict == CheckVerdict::kFail) {
        std::ostringstream msg;
        msg << "gradient check fails (tolerance " << options.gradcheck_tolerance << "):";
        for (const auto& input : check.inputs)
          if (input.verdict == CheckVerdict::kFail) msg << " " << input.input << " " << input.reason << ";";
        return finish("violation", msg.str());
      }
    }
  } catch (const SolverError& e) {
    return finish("failed", Describe(e));
  } catch (const std::exception& e) {
    return finish("violation", std::string("unexpected error: ") + e.what());
  }
  return finish("ok", "");
}

std::vector<std::array<double, 3>> LongCaseCorners(const StressOptions& options) {
  auto extremes = [](const std::vector<double>& values) {
    return std::array<double, 2>{*std::min_element(values.begin(), values.end()),
                                 *std::max_element(values.begin(), values.end())};
  };
  const auto e = extremes(options.youngs_moduli), nu = extremes(options.poissons_ratios),
             h = extremes(options.time_steps);
  // (lo, lo, hi), (lo, hi, lo), (hi, lo, lo), (hi, hi, hi): every pair of
  // axes meets (lo, lo), (lo, hi), (hi, lo) and (hi, hi).
  const int pick[4][3] = {{0, 0, 1}, {0, 1, 0}, {1, 0, 0}, {1, 1, 1}};
  std::vector<std::array<double, 3>> corners;
  for (const auto& p : pick) {
    const std::array<double, 3> corner = {e[p[0]], nu[p[1]], h[p[2]]};
    if (std::find(corners.begin(), corners.end(), corner) == corners.end()) corners.push_back(corner);
  }
  return corners;
}

std::vector<StressCase> RunStress(const StressOptions& options, std::ostream* progress) {
  options.Validate();
  for (const auto& p : options.problems) MakeRefinedProblem(p.name, p.refine);  // fail early on a bad name
  std::vector<StressCase> cases;
  const auto corners = LongCaseCorners(options);
  const size_t grid = options.long_only
                          ? 0
                          : options.problems.size() * options.methods.size() * options.youngs_moduli.size() *
                                options.poissons_ratios.size() * options.time_steps.size();
  const size_t total =
      grid + (options.long_steps > 0 ? options.problems.size() * options.methods.size() * corners.size() : 0);
  auto run = [&](const StressProblem& p, Method method, double e, double nu, double h, int steps) {
    cases.push_back(RunStressCase(p, method, e, nu, h, options, progress, steps));
    if (progress) {
      const StressCase& c = cases.back();
      *progress << "[stress " << cases.size() << "/" << total << "] " << c.problem << " " << c.method << " E=" << e
                << " nu=" << nu << " h=" << h << (steps > 0 ? " (" + std::to_string(steps) + " steps)" : "") << ": "
                << c.outcome << (c.message.empty() ? "" : " (" + c.message + ")") << " " << c.seconds << " s"
                << std::endl;
    }
  };
  if (!options.long_only)
    for (const auto& p : options.problems)
      for (Method method : options.methods)
        for (double e : options.youngs_moduli)
          for (double nu : options.poissons_ratios)
            for (double h : options.time_steps) run(p, method, e, nu, h, 0);
  if (options.long_steps > 0)
    for (const auto& p : options.problems)
      for (Method method : options.methods)
        for (const auto& [e, nu, h] : corners) run(p, method, e, nu, h, options.long_steps);
  return cases;
}

StressSummary SummarizeStress(const std::vector<StressCase>& cases) {
  StressSummary s;
  s.min_gradcheck_margin = std::numeric_limits<double>::infinity();
  for (const auto& c : cases) {
    ++s.cases;
    s.long_cases += c.long_case;
    s.contact_cases += c.contact_steps > 0;
    if (c.outcome == "ok") ++s.ok;
    if (c.outcome == "failed") ++s.failed;
    if (c.outcome == "violation") ++s.violations;
    if (!c.gradcheck_run) continue;
    ++s.gradchecks;
    s.unresolved_cases += !c.gradcheck_unresolved.empty();
    s.tangent_cases += !c.gradcheck_tangent.empty();
    s.min_gradcheck_margin = std::min(s.min_gradcheck_margin, c.gradcheck_margin);
  }
  return s;
}

nlohmann::json StressToJson(const std::vector<StressCase>& cases) {
  auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : cases)
    out.push_back({{"problem", c.problem},
                   {"method", c.method},
                   {"youngs_modulus", c.youngs_modulus},
                   {"poissons_ratio", c.poissons_ratio},
                   {"time_step", c.time_step},
                   {"steps", c.steps},
                   {"long_case", c.long_case},
                   {"outcome", c.outcome},
                   {"message", c.message},
                   {"steps_completed", c.steps_completed},
                   {"rounding_floor_steps", c.rounding_floor_steps},
                   {"newton_fallback_steps", c.newton_fallback_steps},
                   {"contact_steps", c.contact_steps},
                   {"max_contact_nodes", c.max_contact_nodes},
                   {"max_energy_excess", c.max_energy_excess},
                   {"gradcheck_run", c.gradcheck_run},
                   {"gradcheck_error", c.gradcheck_error},
                   {"gradcheck_floor", c.gradcheck_floor},
                   {"gradcheck_margin", number(c.gradcheck_margin)},
                   {"gradcheck_unresolved", c.gradcheck_unresolved},
                   {"gradcheck_tangent", c.gradcheck_tangent},
                   {"gradcheck_tightened", c.gradcheck_tightened},
                   {"gradcheck_reference", c.gradcheck_reference},
                   {"gradcheck_reference_failure", c.gradcheck_reference_failure},
                   {"seconds", c.seconds}});
  return out;
}

}  // namespace diffpd::problems
