#include "stress.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "bench.h"
#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "gradcheck.h"

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

void StressOptions::Validate() const {
  auto fail = [](const std::string& field, double value, const std::string& range) {
    std::ostringstream msg;
    msg << field << " = " << value << " is invalid: must be " << range;
    throw InvalidInputError(msg.str());
  };
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
  if (threads < 0) fail("threads", threads, ">= 0");
  if (max_iterations < 1) fail("max_iterations", max_iterations, ">= 1");
  if (!(energy_tolerance >= 0)) fail("energy_tolerance", energy_tolerance, ">= 0");
  if (gradcheck_steps < 0) fail("gradcheck_steps", gradcheck_steps, ">= 0");
  if (!(gradcheck_tolerance > 0)) fail("gradcheck_tolerance", gradcheck_tolerance, "> 0");
}

StressCase RunStressCase(const StressProblem& problem, Method method, double youngs_modulus, double poissons_ratio,
                         double time_step, const StressOptions& options) {
  StressCase c;
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
    so.num_threads = options.threads;
    so.max_iterations = options.max_iterations;
    Simulator sim(scene, so);
    const int steps = options.steps;
    const VectorXd mass = sim.LumpedMass();
    VectorXd gravity = VectorXd::Zero(sim.num_dofs());
    if (scene.gravity)
      for (int i = 0; i < sim.num_dofs() / 3; ++i) gravity.segment<3>(3 * i) = *scene.gravity;

    Rollout rollout;
    rollout.material = scene.material;
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
      const EnergyParts e = energy(next);
      if (!std::isfinite(e.total())) {
        std::ostringstream msg;
        msg << "step " << k + 1 << " returned a state of non-finite energy without an error";
        return finish("violation", msg.str());
      }
      const double excess = (e.total() - e0.total()) / (e0.magnitude() + e.magnitude() + 1e-300);
      c.max_energy_excess = std::max(c.max_energy_excess, excess);
      rollout.states.push_back(std::move(next));
      c.steps_completed = k + 1;
    }
    if (c.max_energy_excess > options.energy_tolerance) {
      std::ostringstream msg;
      msg << "the total energy rose by " << c.max_energy_excess << " (relative) > energy tolerance "
          << options.energy_tolerance;
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

    const int prefix = std::min(options.gradcheck_steps, steps);
    if (prefix > 0) {
      SolverOptions tight = so;
      tight.rel_tolerance = 1e-10;
      tight.backward_rel_tolerance = 1e-12;
      GradCheckOptions check;
      check.directions = 1;
      check.seed = options.seed;
      GradCheckResult result;
      try {
        result = CheckRolloutGradient(scene, tight, initial, prefix, check);
      } catch (const SolverError& e) {
        return finish("failed", "gradient check (solves at rel_tolerance 1e-10): " + Describe(e));
      }
      c.gradcheck_error = result.max_rel_error;
      if (!(result.max_rel_error <= options.gradcheck_tolerance)) {
        std::ostringstream msg;
        msg << "gradient check: relative error " << result.max_rel_error << " > " << options.gradcheck_tolerance
            << " (";
        for (size_t k = 0; k < result.inputs.size(); ++k)
          msg << (k ? ", " : "") << result.inputs[k].input << " " << result.inputs[k].max_rel_error;
        msg << ")";
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

std::vector<StressCase> RunStress(const StressOptions& options, std::ostream* progress) {
  options.Validate();
  for (const auto& p : options.problems) MakeRefinedProblem(p.name, p.refine);  // fail early on a bad name
  std::vector<StressCase> cases;
  const size_t total = options.problems.size() * options.methods.size() * options.youngs_moduli.size() *
                       options.poissons_ratios.size() * options.time_steps.size();
  for (const auto& p : options.problems)
    for (Method method : options.methods)
      for (double e : options.youngs_moduli)
        for (double nu : options.poissons_ratios)
          for (double h : options.time_steps) {
            cases.push_back(RunStressCase(p, method, e, nu, h, options));
            if (progress) {
              const StressCase& c = cases.back();
              *progress << "[stress " << cases.size() << "/" << total << "] " << c.problem << " " << c.method
                        << " E=" << e << " nu=" << nu << " h=" << h << ": " << c.outcome
                        << (c.message.empty() ? "" : " (" + c.message + ")") << " " << c.seconds << " s"
                        << std::endl;
            }
          }
  return cases;
}

nlohmann::json StressToJson(const std::vector<StressCase>& cases) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& c : cases)
    out.push_back({{"problem", c.problem},
                   {"method", c.method},
                   {"youngs_modulus", c.youngs_modulus},
                   {"poissons_ratio", c.poissons_ratio},
                   {"time_step", c.time_step},
                   {"outcome", c.outcome},
                   {"message", c.message},
                   {"steps_completed", c.steps_completed},
                   {"max_energy_excess", c.max_energy_excess},
                   {"gradcheck_error", c.gradcheck_error},
                   {"seconds", c.seconds}});
  return out;
}

}  // namespace diffpd::problems
