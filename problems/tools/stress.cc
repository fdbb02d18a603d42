#include "tools/stress.h"

#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <sstream>

#include "tools/bench.h"
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
  if (gradcheck_steps < 0) fail("gradcheck_steps", gradcheck_steps, ">= 0");
  if (!(gradcheck_tolerance > 0)) fail("gradcheck_tolerance", gradcheck_tolerance, "> 0");
}

DerivativeVerdict JudgeDerivative(double analytic, const std::vector<FiniteDifference>& differences, double tolerance) {
  DerivativeVerdict verdict;
  verdict.error = std::numeric_limits<double>::infinity();
  bool resolved = false;
  for (const auto& d : differences) {
    const double scale = std::max(std::abs(d.value), std::abs(analytic));
    verdict.error = std::min(verdict.error, scale > 0 ? std::abs(d.value - analytic) / scale : 0.0);
    if (d.noise <= tolerance * scale) resolved = true;
  }
  if (differences.empty()) verdict.error = 0;
  // Agreement within `tolerance` is no coincidence; disagreement counts only
  // where a difference resolves the derivative.
  verdict.tested = !differences.empty() && (verdict.error <= tolerance || resolved);
  return verdict;
}

StressGradientCheck CheckStressGradient(const Scene& scene, const SolverOptions& options, const State& initial,
                                        int steps, std::uint64_t seed, double tolerance) {
  Simulator sim(scene, options);
  const int n = sim.num_dofs();
  const double h = options.time_step;
  const VectorXd mass = sim.LumpedMass();
  const LinearLoss loss = LinearLoss::Random(n, seed);
  std::mt19937_64 rng(seed + 1);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto direction = [&]() {  // random, entries of unit root-mean-square
    VectorXd d(n);
    for (int i = 0; i < n; ++i) d(i) = normal(rng);
    return VectorXd(d * (std::sqrt(double(n)) / d.norm()));
  };
  const std::vector<StepInput> inputs(steps);
  const Rollout rollout = sim.Simulate(initial, inputs);
  LossGradient dl(steps);
  dl.dx[steps] = loss.cx;
  dl.dv[steps] = loss.cv;
  const RolloutGradient g = sim.Backward(rollout, dl);
  const State& last = rollout.states.back();
  // Rounding scale of the loss: sum of |c_i s_i|, v = (x_K - x_{K-1}) / h
  // carrying the rounding of x over h.
  const double loss_magnitude =
      loss.cx.cwiseAbs().dot(last.x.cwiseAbs()) + loss.cv.cwiseAbs().dot(last.v.cwiseAbs() + last.x.cwiseAbs() / h);
  // Estimate of the loss error the solves leave: a residual r moves x by at
  // most r h^2 / m_min (hess g >= M / h^2 at a minimum) and v by that over h;
  // r_k = 10 x step k's final residual (the perturbed rollouts stop at
  // residuals like the base one's; 10 covers the variation).
  double solve_error_x = 0;
  for (const auto& rep : rollout.reports) solve_error_x += 10 * rep.final_residual * h * h / mass.minCoeff();
  const double solve_noise = (loss.cx.norm() + loss.cv.norm() / h) * solve_error_x;
  Eigen::Map<const Eigen::Matrix3Xd> x0(initial.x.data(), 3, n / 3);
  const double size = (x0.rowwise().maxCoeff() - x0.rowwise().minCoeff()).norm();  // m
  const MaterialParameters base = scene.material;

  StressGradientCheck result;
  // perturbed(e) is the loss with the input moved by e (in units of its scale).
  auto record = [&](const std::string& name, double analytic, const std::function<double(double)>& perturbed) {
    std::vector<FiniteDifference> fds;
    for (int k = 2; k <= 7; ++k) {
      const double e = std::pow(10.0, -k);
      const double noise = (1e-13 * loss_magnitude + solve_noise) / e;  // rounding and solve error
      fds.push_back({e, (perturbed(e) - perturbed(-e)) / (2 * e), noise});
    }
    const DerivativeVerdict verdict = JudgeDerivative(analytic, fds, tolerance);
    result.inputs.push_back(name);
    result.errors.push_back(verdict.error);
    result.resolved.push_back(verdict.tested);
    if (verdict.tested) result.max_error = std::max(result.max_error, verdict.error);
  };
  auto rollout_loss = [&](const State& init, const std::vector<StepInput>& in) {
    return loss.Value(sim.Simulate(init, in).states.back());
  };
  auto material_loss = [&](const MaterialParameters& m) {
    sim.SetMaterial(m);
    const double l = rollout_loss(initial, inputs);
    sim.SetMaterial(base);
    return l;
  };
  const VectorXd dx = size * direction();
  record("x0", g.x0.dot(dx), [&](double e) {
    State s = initial;
    s.x += e * dx;
    return rollout_loss(s, inputs);
  });
  const VectorXd dv = (size / h) * direction();
  record("v0", g.v0.dot(dv), [&](double e) {
    State s = initial;
    s.v += e * dv;
    return rollout_loss(s, inputs);
  });
  // A force that moves a node by about `size` in one step: m size / h^2.
  std::vector<VectorXd> df(steps);
  double analytic = 0;
  for (int i = 0; i < steps; ++i) {
    df[i] = (size / (h * h)) * mass.cwiseProduct(direction()) / std::sqrt(double(steps));
    analytic += g.external_force[i].dot(df[i]);
  }
  record("external_force", analytic, [&](double e) {
    std::vector<StepInput> in(steps);
    for (int i = 0; i < steps; ++i) in[i].external_force = e * df[i];
    return rollout_loss(initial, in);
  });
  record("youngs_modulus", g.youngs_modulus * base.youngs_modulus, [&](double e) {
    MaterialParameters m = base;
    m.youngs_modulus *= 1 + e;
    return material_loss(m);
  });
  // Keep nu + e scale inside (-1, 0.5) for e <= 1e-2.
  const double nu_scale = std::min(0.1, 0.5 * (0.5 - base.poissons_ratio));
  record("poissons_ratio", g.poissons_ratio * nu_scale, [&](double e) {
    MaterialParameters m = base;
    m.poissons_ratio += e * nu_scale;
    return material_loss(m);
  });
  record("density", g.density * base.density, [&](double e) {
    MaterialParameters m = base;
    m.density *= 1 + e;
    return material_loss(m);
  });
  return result;
}

StressCase RunStressCase(const StressProblem& problem, Method method, double youngs_modulus, double poissons_ratio,
                         double time_step, const StressOptions& options, std::ostream* progress) {
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
    so.abs_tolerance = options.abs_tolerance > 0 ? options.abs_tolerance : AutoAbsTolerance(scene, time_step);
    so.num_threads = options.threads;
    so.max_iterations = options.max_iterations;
    so.rigid_mode_correction = options.rigid_mode_correction;
    Simulator sim(scene, so);
    const int steps = options.steps;
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
      if (progress && std::chrono::duration<double>(Clock::now() - last_report).count() > 10) {
        last_report = Clock::now();
        *progress << "  ... step " << k + 1 << " of " << steps << std::endl;
      }
    }
    const double energy_tolerance =
        method == Method::kSemiImplicit ? options.explicit_energy_tolerance : options.energy_tolerance;
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

    const int prefix = std::min(options.gradcheck_steps, steps);
    if (prefix > 0) {
      SolverOptions tight = so;
      tight.rel_tolerance = 1e-10;
      tight.backward_rel_tolerance = 1e-12;
      tight.max_iterations = std::max(so.max_iterations, 20000);
      tight.abs_tolerance = AutoAbsTolerance(scene, time_step);
      StressGradientCheck check;
      try {
        check = CheckStressGradient(scene, tight, initial, prefix, options.seed, options.gradcheck_tolerance);
      } catch (const SolverError& e) {
        return finish("failed", "gradient check (solves at rel_tolerance 1e-10): " + Describe(e));
      }
      c.gradcheck_error = check.max_error;
      for (size_t k = 0; k < check.inputs.size(); ++k)
        if (!check.resolved[k]) c.gradcheck_unresolved.push_back(check.inputs[k]);
      if (!(check.max_error <= options.gradcheck_tolerance)) {
        std::ostringstream msg;
        msg << "gradient check: relative error " << check.max_error << " > " << options.gradcheck_tolerance << " (";
        for (size_t k = 0; k < check.inputs.size(); ++k)
          msg << (k ? ", " : "") << check.inputs[k] << " " << check.errors[k];
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
            cases.push_back(RunStressCase(p, method, e, nu, h, options, progress));
            if (progress) {
              const StressCase& c = cases.back();
              *progress << "[stress " << cases.size() << "/" << total << "] " << c.problem << " " << c.method
                        << " E=" << e << " nu=" << nu << " h=" << h << ": " << c.outcome
                        << (c.message.empty() ? "" : " (" + c.message + ")") << " " << c.seconds << " s" << std::endl;
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
                   {"rounding_floor_steps", c.rounding_floor_steps},
                   {"newton_fallback_steps", c.newton_fallback_steps},
                   {"max_energy_excess", c.max_energy_excess},
                   {"gradcheck_error", c.gradcheck_error},
                   {"gradcheck_unresolved", c.gradcheck_unresolved},
                   {"seconds", c.seconds}});
  return out;
}

}  // namespace diffpd::problems
