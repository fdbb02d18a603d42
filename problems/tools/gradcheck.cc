#include "tools/gradcheck.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "diffpd/simulator.h"

namespace diffpd::problems {
namespace {

VectorXd RandomVector(std::mt19937_64* rng, Eigen::Index n) {
  std::normal_distribution<double> normal(0.0, 1.0);
  VectorXd v(n);
  for (Eigen::Index i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

double RelativeError(double a, double b) {
  const double scale = std::max({std::abs(a), std::abs(b), 1e-300});
  return std::abs(a - b) / scale;
}

}  // namespace

GradCheckResult CheckRolloutGradient(const Scene& scene, const SolverOptions& options, const State& initial, int steps,
                                     const GradCheckOptions& check) {
  std::mt19937_64 rng(check.seed);
  Simulator sim(scene, options);
  const int n = sim.num_dofs();
  const VectorXd cx = RandomVector(&rng, n), cv = RandomVector(&rng, n);
  // A non-zero force baseline so that force and density gradients are generic.
  std::vector<StepInput> inputs(steps);
  const double node_force = sim.LumpedMass().maxCoeff() * 9.81;
  for (auto& in : inputs) in.external_force = 0.1 * node_force * RandomVector(&rng, n);
  const int num_muscles = static_cast<int>(scene.muscles.size());
  if (num_muscles > 0)
    for (auto& in : inputs)
      in.activation = VectorXd::Constant(num_muscles, 0.9) + 0.02 * RandomVector(&rng, num_muscles);

  auto loss = [&](Simulator& s, const State& init, const std::vector<StepInput>& in) {
    const Rollout r = s.Simulate(init, in);
    return cx.dot(r.states.back().x) + cv.dot(r.states.back().v);
  };
  const Rollout rollout = sim.Simulate(initial, inputs);
  LossGradient dl(steps);
  dl.dx[steps] = cx;
  dl.dv[steps] = cv;
  const RolloutGradient grad = sim.Backward(rollout, dl);

  GradCheckResult result;
  auto record = [&](const std::string& name, long entries, const std::function<double(double)>& perturbed_loss,
                    double analytic, double eps) {
    GradCheckEntry* entry = nullptr;
    for (auto& e : result.inputs)
      if (e.input == name) entry = &e;
    if (!entry) {
      result.inputs.push_back(GradCheckEntry{name, 0.0, entries, 0});
      entry = &result.inputs.back();
    }
    const double fd = (perturbed_loss(eps) - perturbed_loss(-eps)) / (2 * eps);
    entry->max_rel_error = std::max(entry->max_rel_error, RelativeError(fd, analytic));
    ++entry->directions;
  };
  const double eps_pos = check.relative_step * 0.1;  // m (0.1 m body scale)
  for (int k = 0; k < check.directions; ++k) {
    const VectorXd dx = RandomVector(&rng, n).normalized();
    record(
        "x0", n,
        [&](double e) {
          State s = initial;
          s.x += e * dx;
          return loss(sim, s, inputs);
        },
        grad.x0.dot(dx), eps_pos);
    const VectorXd dv = RandomVector(&rng, n).normalized();
    record(
        "v0", n,
        [&](double e) {
          State s = initial;
          s.v += e * dv;
          return loss(sim, s, inputs);
        },
        grad.v0.dot(dv), eps_pos / options.time_step);
    std::vector<VectorXd> df(steps);
    double analytic = 0;
    for (int i = 0; i < steps; ++i) {
      df[i] = RandomVector(&rng, n) * (node_force / std::sqrt(double(n * steps)));
      analytic += grad.external_force[i].dot(df[i]);
    }
    record(
        "external_force", long(n) * steps,
        [&](double e) {
          std::vector<StepInput> in = inputs;
          for (int i = 0; i < steps; ++i) in[i].external_force += e * df[i];
          return loss(sim, initial, in);
        },
        analytic, 100 * check.relative_step);  // forces act almost linearly: a larger step beats rounding
    if (num_muscles > 0) {
      std::vector<VectorXd> da(steps);
      double analytic_a = 0;
      for (int i = 0; i < steps; ++i) {
        da[i] = RandomVector(&rng, num_muscles) / std::sqrt(double(num_muscles * steps));
        analytic_a += grad.activation[i].dot(da[i]);
      }
      record(
          "activation", long(num_muscles) * steps,
          [&](double e) {
            std::vector<StepInput> in = inputs;
            for (int i = 0; i < steps; ++i) in[i].activation += e * da[i];
            return loss(sim, initial, in);
          },
          analytic_a, check.relative_step);
    }
  }
  // State-force parameters: a fresh simulator per perturbed scene. Forces are
  // linear in them and act almost linearly: a larger step beats rounding.
  const double force_step = 100 * check.relative_step;
  auto scene_loss = [&](const Scene& perturbed) {
    Simulator s(perturbed, options);
    return loss(s, initial, inputs);
  };
  auto record_scene = [&](const std::string& name, const std::function<void(Scene*, double)>& perturb, double analytic,
                          double eps) {
    record(
        name, 1,
        [&](double e) {
          Scene p = scene;
          perturb(&p, e);
          return scene_loss(p);
        },
        analytic, eps);
  };
  if (scene.linear_damping)
    record_scene(
        "linear_damping", [](Scene* p, double e) { *p->linear_damping += e; }, grad.state_forces.linear_damping,
        force_step * std::max(1.0, *scene.linear_damping));
  if (scene.hydrodynamics) {
    const Hydrodynamics& hy = *scene.hydrodynamics;
    record_scene(
        "fluid_density", [](Scene* p, double e) { p->hydrodynamics->fluid_density += e; },
        grad.state_forces.fluid_density, force_step * std::max(1.0, hy.fluid_density));
    record_scene(
        "drag_tangential", [](Scene* p, double e) { p->hydrodynamics->drag_tangential += e; },
        grad.state_forces.drag_tangential, force_step);
    record_scene(
        "drag_normal", [](Scene* p, double e) { p->hydrodynamics->drag_normal += e; }, grad.state_forces.drag_normal,
        force_step);
    record_scene(
        "thrust", [](Scene* p, double e) { p->hydrodynamics->thrust += e; }, grad.state_forces.thrust, force_step);
  }
  bool any_friction = false;
  for (const auto& c : scene.penalty_contacts) any_friction = any_friction || c.friction > 0;
  if (any_friction) {
    double analytic = 0;
    for (size_t c = 0; c < scene.penalty_contacts.size(); ++c)
      if (scene.penalty_contacts[c].friction > 0) analytic += grad.state_forces.penalty_friction[c];
    record_scene(
        "penalty_friction",
        [](Scene* p, double e) {
          for (auto& c : p->penalty_contacts)
            if (c.friction > 0) c.friction += e;
        },
        analytic, force_step);
  }
  const MaterialParameters base = scene.material;
  auto material_loss = [&](MaterialParameters m) {
    sim.SetMaterial(m);
    const double l = loss(sim, initial, inputs);
    sim.SetMaterial(base);
    return l;
  };
  record(
      "youngs_modulus", 1,
      [&](double e) {
        MaterialParameters m = base;
        m.youngs_modulus += e;
        return material_loss(m);
      },
      grad.youngs_modulus, check.relative_step * base.youngs_modulus);
  record(
      "poissons_ratio", 1,
      [&](double e) {
        MaterialParameters m = base;
        m.poissons_ratio += e;
        return material_loss(m);
      },
      grad.poissons_ratio, check.relative_step * 0.1);
  record(
      "density", 1,
      [&](double e) {
        MaterialParameters m = base;
        m.density += e;
        return material_loss(m);
      },
      grad.density, check.relative_step * base.density);
  for (const auto& e : result.inputs) result.max_rel_error = std::max(result.max_rel_error, e.max_rel_error);
  return result;
}

}  // namespace diffpd::problems
