// Forward-mode derivatives of a rollout (Simulator::Tangents).
//
// Implicit methods: the step x_{i+1} = argmin g(x) satisfies
//   grad g = M (x_{i+1} - x_i - h v_i) / h^2 - f + grad E(x_{i+1}; mu, lambda) = 0,
// so, differentiating along a direction,
//   H dx_{i+1} = M (dx_i + h dv_i) / h^2 + df - grad E(x_{i+1}; dmu_e, dlambda_e)
//                - dM [(x_{i+1} - x_i - h v_i) / h^2 - g],
// with grad E(x; dmu_e, dlambda_e) the elastic gradient evaluated with the
// direction's Lame components per element (E is linear in each element's
// (mu_e, lambda_e); per material part p: dmu_p = dmu/dE_p dE_p + dmu/dnu_p dnu_p,
// likewise lambda), dM = sum_p drho_p m_p the mass direction (m_p the part's
// unit-density lumped mass) and g gravity (when declared). All directions
// share the step's H (one StepLinearization, several right-hand sides).
// Semi-implicit Euler: on free DoFs v_{i+1} = v_i + h M^{-1} (f - grad E(x_i)),
//   dv_{i+1} = dv_i + h M^{-1} (df - hess E dx_i - grad E(x_i; dmu_e, dlambda_e))
//              - h dM M^{-2} (f_user - grad E).
// Both: x_{i+1} is the prescribed value at fixed DoFs (zero tangent there) and
// v_{i+1} = (x_{i+1} - x_i) / h everywhere.
// Muscles: grad E is affine in the activations (E = k/2 vol (|F m| - a)^2), so
// d(grad E)/da . da = grad E(a + da) - grad E(a) exactly. Frictional contact:
// the step's recorded active set is held fixed (as in Backward); a pinned node
// moves with its pin, dx = dpin/dx_i dx_i + dpin/dv_i dv_i, and the free DoFs
// solve H_ff dx_f = b_f - H_fp dx_p. Explicit state forces f(x_i, v_i; M,
// theta) (damping, hydrodynamics on triangles or on one-sided quads, penalty
// friction) enter both methods' force directions as df = df/dx dx_i + df/dv dv_i + df/dM dM + df/dtheta
// dtheta (their Jacobian-vector products).
#include <chrono>
#include <functional>
#include <cmath>
#include <optional>
#include <sstream>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/tangent_rollout.h"
#include "contact/active_set_step.h"
#include "forces/activation_scope.h"
#include "solver/adjoint_tolerance.h"
#include "solver/forward_options_scope.h"
#include "solver/rollout_checks.h"
#include "solver/simulator_impl.h"

namespace diffpd {

InputDirection InputDirection::YoungsModulus() {
  InputDirection d;
  d.youngs_modulus = 1;
  return d;
}

InputDirection InputDirection::PoissonsRatio() {
  InputDirection d;
  d.poissons_ratio = 1;
  return d;
}

InputDirection InputDirection::Density() {
  InputDirection d;
  d.density = 1;
  return d;
}

namespace {

InputDirection RegionDirection(int region, int num_regions, double MaterialComponents::*component) {
  if (region < 0 || region >= num_regions) {
    std::ostringstream msg;
    msg << "InputDirection: region " << region << " is out of range [0, " << num_regions << ")";
    throw InvalidInputError(msg.str());
  }
  InputDirection d;
  d.region_materials.assign(num_regions, MaterialComponents());
  d.region_materials[region].*component = 1;
  return d;
}

}  // namespace

InputDirection InputDirection::RegionYoungsModulus(int region, int num_regions) {
  return RegionDirection(region, num_regions, &MaterialComponents::youngs_modulus);
}

InputDirection InputDirection::RegionPoissonsRatio(int region, int num_regions) {
  return RegionDirection(region, num_regions, &MaterialComponents::poissons_ratio);
}

InputDirection InputDirection::RegionDensity(int region, int num_regions) {
  return RegionDirection(region, num_regions, &MaterialComponents::density);
}

namespace {

using internal::SimulatorImpl;

void CheckDirectionVector(const VectorXd& v, int n, int p, const char* name) {
  if (v.size() == 0) return;
  if (v.size() != n) {
    std::ostringstream msg;
    msg << "Tangents: direction " << p << " has " << name << " with " << v.size() << " entries, expected " << n
        << " (3 x number of nodes)";
    throw InvalidInputError(msg.str());
  }
  if (!v.allFinite()) {
    std::ostringstream msg;
    msg << "Tangents: direction " << p << " has a non-finite entry in " << name;
    throw InvalidInputError(msg.str());
  }
}

void CheckDirections(const std::vector<InputDirection>& dirs, int n, int steps, int num_muscles, int num_regions) {
  if (dirs.empty()) throw InvalidInputError("Tangents: no direction given (need at least one)");
  for (size_t p = 0; p < dirs.size(); ++p) {
    const InputDirection& d = dirs[p];
    const int ip = static_cast<int>(p);
    CheckDirectionVector(d.x0, n, ip, "x0");
    CheckDirectionVector(d.v0, n, ip, "v0");
    if (!d.external_force.empty() && static_cast<int>(d.external_force.size()) != steps) {
      std::ostringstream msg;
      msg << "Tangents: direction " << p << " has external_force for " << d.external_force.size()
          << " steps, expected 0 or " << steps;
      throw InvalidInputError(msg.str());
    }
    for (const VectorXd& f : d.external_force) CheckDirectionVector(f, n, ip, "external_force");
    if (!d.activation.empty() && static_cast<int>(d.activation.size()) != steps) {
      std::ostringstream msg;
      msg << "Tangents: direction " << p << " has activation for " << d.activation.size() << " steps, expected 0 or "
          << steps;
      throw InvalidInputError(msg.str());
    }
    for (const VectorXd& a : d.activation) {
      if (a.size() != 0 && a.size() != num_muscles) {
        std::ostringstream msg;
        msg << "Tangents: direction " << p << " has an activation with " << a.size() << " entries, expected "
            << num_muscles << " (one per muscle)";
        throw InvalidInputError(msg.str());
      }
      if (!a.allFinite()) {
        std::ostringstream msg;
        msg << "Tangents: direction " << p << " has a non-finite entry in activation";
        throw InvalidInputError(msg.str());
      }
    }
    if (!std::isfinite(d.youngs_modulus) || !std::isfinite(d.poissons_ratio) || !std::isfinite(d.density)) {
      std::ostringstream msg;
      msg << "Tangents: direction " << p << " has a non-finite material component";
      throw InvalidInputError(msg.str());
    }
    if (!d.region_materials.empty() && static_cast<int>(d.region_materials.size()) != num_regions) {
      std::ostringstream msg;
      msg << "Tangents: direction " << p << " has region_materials for " << d.region_materials.size()
          << " regions, expected 0 or " << num_regions << " (one per material region)";
      throw InvalidInputError(msg.str());
    }
    for (size_t r = 0; r < d.region_materials.size(); ++r) {
      const MaterialComponents& c = d.region_materials[r];
      if (!std::isfinite(c.youngs_modulus) || !std::isfinite(c.poissons_ratio) || !std::isfinite(c.density)) {
        std::ostringstream msg;
        msg << "Tangents: direction " << p << " has a non-finite material component for region " << r;
        throw InvalidInputError(msg.str());
      }
    }
  }
}

// Throws unless every direction's state-force components are finite and
// zero for the terms the scene does not declare.
void CheckStateForceDirections(const std::vector<InputDirection>& dirs, const Scene& scene) {
  const int contacts = static_cast<int>(scene.penalty_contacts.size());
  for (size_t p = 0; p < dirs.size(); ++p) {
    const StateForceGradient& d = dirs[p].state_forces;
    std::ostringstream msg;
    msg << "Tangents: direction " << p << " ";
    const double hydro[4] = {d.fluid_density, d.drag_tangential, d.drag_normal, d.thrust};
    const QuadHydrodynamicsGradient& quad = d.quad_hydrodynamics;
    bool finite = std::isfinite(d.linear_damping) && d.flow_velocity.allFinite() && std::isfinite(quad.fluid_density) &&
                  quad.flow_velocity.allFinite() && quad.drag_curve.allFinite() && quad.thrust_curve.allFinite();
    for (const double c : hydro) finite = finite && std::isfinite(c);
    for (const double c : d.penalty_friction) finite = finite && std::isfinite(c);
    if (!finite) {
      msg << "has a non-finite state-force component";
      throw InvalidInputError(msg.str());
    }
    if (d.linear_damping != 0 && !scene.linear_damping) {
      msg << "has a linear_damping component, but the scene declares no linear damping";
      throw InvalidInputError(msg.str());
    }
    bool any_hydro = !d.flow_velocity.isZero(0);
    for (const double c : hydro) any_hydro = any_hydro || c != 0;
    if (any_hydro && !scene.hydrodynamics) {
      msg << "has a hydrodynamics component, but the scene declares no hydrodynamics";
      throw InvalidInputError(msg.str());
    }
    const bool any_quad = quad.fluid_density != 0 || !quad.flow_velocity.isZero(0) || !quad.drag_curve.isZero(0) ||
                          !quad.thrust_curve.isZero(0);
    if (any_quad && !scene.quad_hydrodynamics) {
      msg << "has a quad_hydrodynamics component, but the scene declares no quad hydrodynamics";
      throw InvalidInputError(msg.str());
    }
    if (!d.penalty_friction.empty() && static_cast<int>(d.penalty_friction.size()) != contacts) {
      msg << "has penalty_friction for " << d.penalty_friction.size() << " contacts, expected 0 or " << contacts
          << " (one per penalty contact)";
      throw InvalidInputError(msg.str());
    }
  }
}

// The material components of direction d for material part `part` (0: the
// base material, r + 1: region r).
MaterialComponents PartComponents(const InputDirection& d, int part) {
  if (part == 0) {
    MaterialComponents c;
    c.youngs_modulus = d.youngs_modulus;
    c.poissons_ratio = d.poissons_ratio;
    c.density = d.density;
    return c;
  }
  return d.region_materials.empty() ? MaterialComponents() : d.region_materials[part - 1];
}

}  // namespace

namespace {

// The states and report of step i as the tangent pass meets them (i = 0,
// 1, ..., K - 1 in order; report nullptr: none). The pointers stay valid
// until the next call.
struct TangentStep {
  const State* s0 = nullptr;
  const State* s1 = nullptr;
  const StepReport* report = nullptr;
};
using TangentStepSource = std::function<TangentStep(int i)>;

// The pass over K = inputs.size() steps of a rollout made with `forward`
// options (their tolerance and SVD warm start), the states from `step_at`. With a
// consumer, each state's tangents go to it as they are computed and the
// result's dx and dv stay empty.
TangentRollout TangentPass(SimulatorImpl& sim, const std::vector<StepInput>& inputs, const SolverOptions& forward,
                           const State& initial, const TangentStepSource& step_at,
                           const std::vector<InputDirection>& directions, const TangentConsumer& consumer) {
  const auto start = std::chrono::steady_clock::now();
  const int n = sim.num_dofs();
  const int steps = static_cast<int>(inputs.size());
  CheckDirections(directions, n, steps, sim.aux.num_muscles(), static_cast<int>(sim.scene.material_regions.size()));
  CheckStateForceDirections(directions, sim.scene);
  const bool contact = !sim.scene.frictional_contacts.empty() && sim.options.method != Method::kSemiImplicit;
  std::vector<const ContactSurface*> surface_of(n / 3, nullptr);
  for (const FrictionalContact& c : sim.scene.frictional_contacts)
    for (const int node : c.nodes) surface_of[node] = &c.surface;

  const int num_dirs = static_cast<int>(directions.size());
  const double h = sim.h();
  const VectorXd& mass = sim.Mass();
  // Per direction and material part: Lame components and density component.
  const int parts = sim.num_parts();
  MatrixXd dmu(parts, num_dirs), dlambda(parts, num_dirs), drho(parts, num_dirs);
  for (int q = 0; q < parts; ++q) {
    double dmu_dE, dmu_dnu, dl_dE, dl_dnu;
    sim.part_material(q).LameDerivatives(&dmu_dE, &dmu_dnu, &dl_dE, &dl_dnu);
    for (int p = 0; p < num_dirs; ++p) {
      const MaterialComponents c = PartComponents(directions[p], q);
      dmu(q, p) = dmu_dE * c.youngs_modulus + dmu_dnu * c.poissons_ratio;
      dlambda(q, p) = dl_dE * c.youngs_modulus + dl_dnu * c.poissons_ratio;
      drho(q, p) = c.density;
    }
  }
  // The Lame field of each direction (uniform with one part, else per
  // element) and its mass direction dM (3n); skipped where zero.
  std::vector<char> lame_dir(num_dirs), mass_dir(num_dirs);
  std::vector<std::vector<double>> field_mu(num_dirs), field_lambda(num_dirs);
  std::vector<VectorXd> dmass(num_dirs);
  for (int p = 0; p < num_dirs; ++p) {
    lame_dir[p] = dmu.col(p).any() || dlambda.col(p).any();
    mass_dir[p] = drho.col(p).any();
    if (mass_dir[p]) dmass[p] = sim.mass_model.Direction(drho.col(p));
    if (lame_dir[p] && parts > 1) {
      field_mu[p].resize(sim.part_of_element.size());
      field_lambda[p].resize(sim.part_of_element.size());
      for (size_t e = 0; e < sim.part_of_element.size(); ++e) {
        field_mu[p][e] = dmu(sim.part_of_element[e], p);
        field_lambda[p][e] = dlambda(sim.part_of_element[e], p);
      }
    }
  }
  auto lame_field = [&](int p) {
    return parts > 1 ? internal::LameField::PerElement(field_mu[p].data(), field_lambda[p].data())
                     : internal::LameField::Uniform(dmu(0, p), dlambda(0, p));
  };
  // *b.col(p) -= grad E(x; direction p's Lame field) for every direction with one,
  // from the same element forces as the reverse pass's (ElasticForces::PartLameDots).
  VectorXd grad_dir;
  auto subtract_lame_terms = [&](const VectorXd& x, MatrixXd* b) {
    for (int p = 0; p < num_dirs; ++p) {
      if (!lame_dir[p]) continue;
      sim.elastic.LameDirectionGradient(x, lame_field(p), &grad_dir, sim.threads());
      b->col(p) -= grad_dir;
    }
  };
  const VectorXd gravity = internal::GravityPerDof(sim);
  std::vector<StateForceGradient> state_force_dirs(num_dirs);
  for (int p = 0; p < num_dirs; ++p) state_force_dirs[p] = directions[p].state_forces;

  TangentRollout out;
  out.dx.resize(consumer ? 1 : steps + 1);
  out.dv.resize(consumer ? 1 : steps + 1);
  out.dx[0] = MatrixXd::Zero(n, num_dirs);
  out.dv[0] = MatrixXd::Zero(n, num_dirs);
  for (int p = 0; p < num_dirs; ++p) {
    if (directions[p].x0.size()) out.dx[0].col(p) = directions[p].x0;
    if (directions[p].v0.size()) out.dv[0].col(p) = directions[p].v0;
  }

  const bool implicit = sim.options.method != Method::kSemiImplicit;
  // d(grad E)/da . da at x for every direction with an activation at step i
  // (muscle gradients are affine in the activations), subtracted from *b.
  auto subtract_activation_terms = [&](int i, const VectorXd& x, MatrixXd* b) {
    const int muscles = sim.aux.num_muscles();
    if (muscles == 0) return;
    VectorXd base_activation = sim.activation.size() ? sim.activation : VectorXd::Ones(muscles);
    VectorXd g0 = VectorXd::Zero(n);
    bool have_g0 = false;
    for (int p = 0; p < num_dirs; ++p) {
      const InputDirection& d = directions[p];
      if (d.activation.empty() || d.activation[i].size() == 0) continue;
      if (!have_g0) {
        sim.aux.muscles().AddEnergyAndGradient(x, base_activation, &g0);
        have_g0 = true;
      }
      VectorXd g1 = VectorXd::Zero(n);
      sim.aux.muscles().AddEnergyAndGradient(x, base_activation + d.activation[i], &g1);
      b->col(p) -= g1 - g0;
    }
  };

  // The tangents solved so far: the next step's initial guess.
  internal::AdjointRecycling recycling(sim.options.adjoint_guess_solutions);
  // With a consumer only the latest tangents are kept (in out.dx[0], dv[0]).
  if (consumer) consumer(0, initial, out.dx[0], out.dv[0]);
  for (int i = 0; i < steps; ++i) {
    const TangentStep at = step_at(i);
    const State& s0 = *at.s0;
    const State& s1 = *at.s1;
    const int from = consumer ? 0 : i;
    const MatrixXd& dx0 = out.dx[from];
    const MatrixXd& dv0 = out.dv[from];
    const internal::ActivationScope activation(sim, inputs[i].activation);
    // Cold SVDs where the forward had them: the step's tangents depend on its
    // states alone (a checkpointed rollout's states are recomputed in between).
    if (!forward.svd_warm_start) sim.elastic.ResetWarmStart();
    MatrixXd dx1;
    if (implicit) {
      // Right-hand sides: inertia through xhat, force directions, parameters.
      MatrixXd b = mass.asDiagonal() * (dx0 + h * dv0) / (h * h);
      subtract_lame_terms(s1.x, &b);
      if (drho.any()) {
        const VectorXd dgrad_dmass = (s1.x - s0.x - h * s0.v) / (h * h) - gravity;
        for (int p = 0; p < num_dirs; ++p)
          if (mass_dir[p]) b.col(p) -= dmass[p].cwiseProduct(dgrad_dmass);
      }
      for (int p = 0; p < num_dirs; ++p)
        if (!directions[p].external_force.empty() && directions[p].external_force[i].size())
          b.col(p) += directions[p].external_force[i];
      sim.state_forces.AddJvp(s0.x, s0.v, mass, inputs[i].wetted_quads, dx0, dv0, dmass, state_force_dirs, &b);
      subtract_activation_terms(i, s1.x, &b);
      const std::vector<int> no_pins;
      const std::vector<int>& pinned = contact ? at.report->contact_nodes : no_pins;
      MatrixXd dpin = MatrixXd::Zero(n, num_dirs);
      if (!pinned.empty()) {
        // Pinned nodes follow their pins; move their coupling to the right.
        for (const int node : pinned) {
          DIFFPD_CHECK(surface_of[node] != nullptr, "pinned node " << node << " is not a frictional contact candidate");
          const internal::ContactPin pin =
              internal::ComputeContactPin(*surface_of[node], s0.x.segment<3>(3 * node), s0.v.segment<3>(3 * node), h);
          dpin.middleRows<3>(3 * node) =
              pin.d_dx * dx0.middleRows<3>(3 * node) + pin.d_dv * dv0.middleRows<3>(3 * node);
        }
        internal::StepLinearization coupling(sim, s1.x);  // pinned nodes still free here
        for (int p = 0; p < num_dirs; ++p) b.col(p) -= coupling.ApplyUnmasked(dpin.col(p));
      }
      std::optional<internal::ContactPinScope> pins;
      if (!pinned.empty()) pins.emplace(sim, pinned, s1.x);
      internal::StepLinearization lin(sim, s1.x);
      lin.set_recycling(&recycling);
      lin.set_steps_left(steps - i);
      lin.set_rel_tolerance(internal::AdjointRelTolerance(sim.options, forward.rel_tolerance, at.report));
      dx1 = lin.SolveColumns(b, &out.report) + dpin;  // zero at fixed DoFs but the pins
    } else {
      // Acceleration tangent on free DoFs, then symplectic update.
      std::vector<Mat9> dstress;
      sim.elastic.StressDifferentials(s0.x, sim.lame(), &dstress, sim.threads());
      MatrixXd force(n, num_dirs);
      for (int p = 0; p < num_dirs; ++p) {
        VectorXd hdx;
        sim.elastic.ApplyHessian(dstress, dx0.col(p), &hdx, sim.threads());
        sim.aux.AddHessianProduct(s0.x, sim.activation, dx0.col(p), &hdx);
        force.col(p) = -hdx;
        if (!directions[p].external_force.empty() && directions[p].external_force[i].size())
          force.col(p) += directions[p].external_force[i];
      }
      sim.state_forces.AddJvp(s0.x, s0.v, mass, inputs[i].wetted_quads, dx0, dv0, dmass, state_force_dirs, &force);
      subtract_lame_terms(s0.x, &force);
      subtract_activation_terms(i, s0.x, &force);
      MatrixXd dv1 = dv0 + h * mass.cwiseInverse().asDiagonal() * force;
      if (drho.any()) {
        VectorXd grad_e;
        sim.elastic.EnergyAndGradient(s0.x, sim.lame(), &grad_e, sim.threads());
        sim.aux.AddEnergyAndGradient(s0.x, sim.activation, &grad_e);
        const VectorXd& user = inputs[i].external_force;
        VectorXd force_sum = user.size() ? user : VectorXd::Zero(n);
        sim.state_forces.Add(s0.x, s0.v, mass, inputs[i].wetted_quads, &force_sum);
        const VectorXd net = (force_sum - grad_e).cwiseQuotient(mass.cwiseAbs2());
        for (int p = 0; p < num_dirs; ++p)
          if (mass_dir[p]) dv1.col(p) -= h * dmass[p].cwiseProduct(net);
      }
      dx1 = dx0 + h * dv1;
      for (int d = 0; d < n; ++d)
        if (sim.fixed[d]) dx1.row(d).setZero();
    }
    MatrixXd dv1 = (dx1 - dx0) / h;
    if (!dx1.allFinite() || !dv1.allFinite())
      throw SolverError(SolverStatus::kNonFinite, "the tangent of state " + std::to_string(i + 1) + " is not finite");
    if (consumer) {
      consumer(i + 1, s1, dx1, dv1);
      out.dx[0] = std::move(dx1);
      out.dv[0] = std::move(dv1);
    } else {
      out.dv[i + 1] = std::move(dv1);
      out.dx[i + 1] = std::move(dx1);
    }
  }
  if (!out.dx[0].allFinite() || !out.dv[0].allFinite())
    throw SolverError(SolverStatus::kNonFinite, "the tangent of state 0 is not finite");
  if (consumer) {
    out.dx.clear();
    out.dv.clear();
  }
  out.report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

// Runs `pass`, reporting a non-finite value on the way as an overflow (the
// rollout and directions were checked finite).
TangentRollout WithOverflowMessage(const SimulatorImpl& sim, const std::function<TangentRollout()>& pass) {
  try {
    return pass();
  } catch (const SolverError& e) {
    if (e.status() != SolverStatus::kNonFinite) throw;
    throw SolverError(SolverStatus::kNonFinite, std::string(ToString(sim.options.method)) +
                                                    " tangent: the tangents overflowed double precision (" + e.what() +
                                                    ")");
  }
}

}  // namespace

TangentRollout Simulator::Tangents(const Rollout& rollout, const std::vector<InputDirection>& directions) {
  internal::CheckRolloutForDerivatives(*impl_, rollout, "Tangents");
  const bool with_reports = rollout.reports.size() == rollout.inputs.size();
  const TangentStepSource step_at = [&rollout, with_reports](int i) {
    return TangentStep{&rollout.states[i], &rollout.states[i + 1], with_reports ? &rollout.reports[i] : nullptr};
  };
  return WithOverflowMessage(*impl_, [&] {
    return TangentPass(*impl_, rollout.inputs, rollout.options, rollout.states[0], step_at, directions, nullptr);
  });
}

TangentRollout Simulator::Tangents(const CheckpointedRollout& rollout, const std::vector<InputDirection>& directions,
                                   const TangentConsumer& consumer) {
  internal::CheckCheckpointedRollout(*impl_, rollout, "Tangents");
  // The states are recomputed step by step with the forward's options.
  State s0, s1 = rollout.initial;
  StepReport report;
  const TangentStepSource step_at = [&](int i) {
    s0 = std::move(s1);
    const internal::ForwardOptionsScope forward(*impl_, rollout.options);
    s1 = Step(s0, rollout.inputs[i], &report);
    return TangentStep{&s0, &s1, &report};
  };
  return WithOverflowMessage(*impl_, [&] {
    return TangentPass(*impl_, rollout.inputs, rollout.options, rollout.initial, step_at, directions, consumer);
  });
}

}  // namespace diffpd
