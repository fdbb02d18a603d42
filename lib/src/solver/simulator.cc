#include "diffpd/simulator.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "contact/active_set_step.h"
#include "diffpd/error.h"
#include "forces/activation_scope.h"
#include "solver/adjoint_tolerance.h"
#include "solver/energy_bounded_step.h"
#include "solver/rollout_checks.h"
#include "solver/simulator_impl.h"

namespace diffpd {
namespace {

using internal::SimulatorImpl;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void CheckVector(const VectorXd& v, Eigen::Index size, const char* name, bool allow_empty) {
  if (allow_empty && v.size() == 0) return;
  if (v.size() != size) {
    std::ostringstream msg;
    msg << name << " has " << v.size() << " entries, expected " << size << " (3 x number of nodes)";
    throw InvalidInputError(msg.str());
  }
  if (!v.allFinite()) throw InvalidInputError(std::string(name) + " has a non-finite entry");
}

bool IsImplicit(Method m) { return m != Method::kSemiImplicit; }

// SolverOptions::max_extent_ratio: throws SolverError(kDiverged) when the
// nodes' bounding box at positions x is too large.
void CheckExtent(const SimulatorImpl& sim, const VectorXd& x) {
  const double bound = sim.options.max_extent_ratio * sim.rest_extent;
  if (std::isinf(bound)) return;
  const Eigen::Map<const Eigen::Matrix3Xd> nodes(x.data(), 3, x.size() / 3);
  const double extent = (nodes.rowwise().maxCoeff() - nodes.rowwise().minCoeff()).norm();
  if (extent <= bound) return;
  std::ostringstream msg;
  msg << ToString(sim.options.method) << ": the step diverged: the body's extent (its bounding box's diagonal) grew to "
      << extent << " m, beyond max_extent_ratio = " << sim.options.max_extent_ratio << " times its rest extent "
      << sim.rest_extent << " m (h = " << sim.h() << " s"
      << (IsImplicit(sim.options.method) ? ")" : "; an explicit method needs a smaller time step)");
  throw SolverError(SolverStatus::kDiverged, msg.str());
}

}  // namespace

Simulator::Simulator(const Scene& scene, const SolverOptions& options)
    : impl_(std::make_unique<SimulatorImpl>(scene, options)) {}
Simulator::~Simulator() = default;

const Scene& Simulator::scene() const { return impl_->scene; }
const SolverOptions& Simulator::options() const { return impl_->options; }
int Simulator::num_dofs() const { return impl_->num_dofs(); }

void Simulator::SetOptions(const SolverOptions& options) {
  options.Validate();
  impl_->options = options;
  impl_->ResetAdjointCostModels();
}

void Simulator::SetMaterial(const MaterialParameters& material) {
  material.Validate();
  impl_->SetMaterial(material);
}

void Simulator::SetRegionMaterial(int region, const MaterialParameters& material) {
  const int regions = static_cast<int>(impl_->scene.material_regions.size());
  if (region < 0 || region >= regions) {
    std::ostringstream msg;
    msg << "SetRegionMaterial: region " << region << " is out of range [0, " << regions << ")";
    throw InvalidInputError(msg.str());
  }
  try {
    material.Validate();
  } catch (const InvalidInputError& e) {
    std::ostringstream msg;
    msg << "SetRegionMaterial: region " << region << ": " << e.what();
    throw InvalidInputError(msg.str());
  }
  impl_->SetRegionMaterial(region, material);
}

State Simulator::RestState() const {
  State s;
  s.x = Eigen::Map<const VectorXd>(impl_->scene.mesh.vertices.data(), impl_->num_dofs());
  for (size_t k = 0; k < impl_->scene.dirichlet.dofs.size(); ++k)
    s.x(impl_->scene.dirichlet.dofs[k]) = impl_->scene.dirichlet.values(k);
  s.v = VectorXd::Zero(impl_->num_dofs());
  return s;
}

VectorXd Simulator::LumpedMass() const { return impl_->Mass(); }

double Simulator::ElasticEnergy(const VectorXd& x) {
  CheckVector(x, impl_->num_dofs(), "positions", false);
  return impl_->elastic.EnergyAndGradient(x, impl_->lame(), nullptr, impl_->threads());
}

int Simulator::num_pd_factorizations() const {
  // The PD system exists only once a PD method has stepped.
  return impl_->pd_factorizations();
}

double Simulator::pd_factorization_seconds() const { return impl_->pd_factorization_seconds(); }

State Simulator::Step(const State& state, const StepInput& input, StepReport* report) {
  SimulatorImpl& sim = *impl_;
  const int n = sim.num_dofs();
  CheckVector(state.x, n, "state.x", false);
  CheckVector(state.v, n, "state.v", false);
  CheckVector(input.external_force, n, "external_force", true);
  internal::CheckActivation(input.activation, sim.aux.num_muscles());
  const internal::ActivationScope activation(sim, input.activation);
  const auto start = Clock::now();
  StepReport local;
  StepReport* rep = report ? report : &local;
  *rep = StepReport();
  const double h = sim.h();
  VectorXd f = sim.ExplicitForce(input);
  sim.state_forces.Add(state.x, state.v, sim.Mass(), &f);
  State next;
  if (sim.options.method == Method::kSemiImplicit) {
    if (!sim.scene.frictional_contacts.empty())
      throw InvalidInputError(
          "semi-implicit: frictional contact needs an implicit method (newton-cholesky, "
          "newton-pcg, pd, pd-lbfgs); use penalty contact instead");
    VectorXd grad;
    sim.elastic.EnergyAndGradient(state.x, sim.lame(), &grad, sim.threads());
    sim.aux.AddEnergyAndGradient(state.x, sim.activation, &grad);
    next.v = state.v + h * ((f - grad).array() / sim.Mass().array()).matrix();
    next.x = state.x + h * next.v;
  } else {
    const internal::ImplicitSolver solve = [&sim](internal::StepObjective& objective, const VectorXd& x0,
                                                  StepReport* r) -> VectorXd {
      switch (sim.options.method) {
        case Method::kNewtonCholesky:
        case Method::kNewtonPcg:
        case Method::kNewtonLdlt:
          return internal::NewtonSolve(objective, x0, r);
        case Method::kPd:
          return internal::PdSolve(objective, x0, r);
        case Method::kPdLbfgs:
          return internal::PdLbfgsSolve(objective, x0, r);
        case Method::kSemiImplicit:
          break;
      }
      return x0;
    };
    if (!sim.scene.frictional_contacts.empty()) {
      next.x = internal::SolveWithActiveSet(sim, state, f, solve, rep);
    } else {
      VectorXd x0 = state.x + h * state.v, previous = state.x;
      for (int d = 0; d < n; ++d)
        if (sim.fixed[d]) x0(d) = previous(d) = sim.fixed_values(d);
      internal::StepObjective objective(sim, state.x + h * state.v, f);
      next.x = internal::SolveEnergyBounded(objective, x0, previous, solve, rep);
    }
  }
  for (int d = 0; d < n; ++d)
    if (sim.fixed[d]) next.x(d) = sim.fixed_values(d);
  next.v = (next.x - state.x) / h;
  if (!next.x.allFinite() || !next.v.allFinite()) {
    std::ostringstream msg;
    msg << ToString(sim.options.method) << ": the state became non-finite (h = " << h
        << " s; an explicit method needs a smaller time step)";
    throw SolverError(SolverStatus::kNonFinite, msg.str());
  }
  CheckExtent(sim, next.x);
  rep->seconds = Seconds(start);
  if (sim.options.verbosity >= 1)
    std::fprintf(stderr, "%s step: %d iterations, |grad g| %.3e -> %.3e, %.4f s\n", ToString(sim.options.method),
                 rep->iterations, rep->initial_residual, rep->final_residual, rep->seconds);
  return next;
}

Rollout Simulator::Simulate(const State& initial, const std::vector<StepInput>& inputs) {
  // Every input is checked before the first step, so that a bad one is
  // named by its index and costs no simulation.
  for (size_t i = 0; i < inputs.size(); ++i) {
    try {
      CheckVector(inputs[i].external_force, impl_->num_dofs(), "external_force", true);
      internal::CheckActivation(inputs[i].activation, impl_->aux.num_muscles());
    } catch (const InvalidInputError& e) {
      throw InvalidInputError("Simulate: inputs[" + std::to_string(i) + "]: " + e.what());
    }
  }
  Rollout r;
  r.material = impl_->scene.material;
  for (const MaterialRegion& region : impl_->scene.material_regions) r.region_materials.push_back(region.material);
  r.options = impl_->options;
  r.inputs = inputs;
  r.states.reserve(inputs.size() + 1);
  r.reports.resize(inputs.size());
  r.states.push_back(initial);
  for (size_t i = 0; i < inputs.size(); ++i) r.states.push_back(Step(r.states.back(), inputs[i], &r.reports[i]));
  return r;
}

Rollout Simulator::Simulate(const State& initial, const Controller& controller, int steps) {
  if (steps < 0) {
    std::ostringstream msg;
    msg << "Simulate: steps = " << steps << " is invalid: must be >= 0";
    throw InvalidInputError(msg.str());
  }
  const int n = impl_->num_dofs();
  const int memory_size = controller.memory_size();
  Rollout r;
  r.material = impl_->scene.material;
  for (const MaterialRegion& region : impl_->scene.material_regions) r.region_materials.push_back(region.material);
  r.options = impl_->options;
  r.controller_parameters = controller.parameters();
  r.states.reserve(steps + 1);
  r.inputs.reserve(steps);
  r.controller_memory.reserve(steps + 1);
  r.reports.resize(steps);
  r.states.push_back(initial);
  r.controller_memory.push_back(controller.InitialMemory());
  auto check_memory = [memory_size](const VectorXd& m, const std::string& when) {
    if (m.size() != memory_size) {
      std::ostringstream msg;
      msg << "Simulate: the controller's memory " << when << " has " << m.size() << " entries, expected "
          << memory_size;
      throw InvalidInputError(msg.str());
    }
    if (!m.allFinite())
      throw InvalidInputError("Simulate: the controller's memory " + when + " has a non-finite entry");
  };
  check_memory(r.controller_memory[0], "before step 0");
  for (int k = 0; k < steps; ++k) {
    ControlAction action;
    VectorXd next_memory;
    controller.Act(k, r.states.back(), r.controller_memory.back(), &action, &next_memory);
    StepInput input;
    input.activation = std::move(action.activation);
    input.external_force = std::move(action.external_force);
    try {
      CheckVector(input.external_force, n, "external_force", true);
      internal::CheckActivation(input.activation, impl_->aux.num_muscles());
    } catch (const InvalidInputError& e) {
      std::ostringstream msg;
      msg << "Simulate: the controller's action at step " << k << ": " << e.what();
      throw InvalidInputError(msg.str());
    }
    check_memory(next_memory, "after step " + std::to_string(k));
    r.states.push_back(Step(r.states.back(), input, &r.reports[k]));
    r.inputs.push_back(std::move(input));
    r.controller_memory.push_back(std::move(next_memory));
  }
  return r;
}

namespace {

// Backward's pass over the steps, given a checked rollout (and, closed
// loop, the controller that made it).
RolloutGradient BackwardPass(SimulatorImpl& sim, const Rollout& rollout, const LossGradient& loss,
                             const Controller* controller) {
  const auto start = Clock::now();
  const int n = sim.num_dofs();
  const int steps = rollout.num_steps();
  if (static_cast<int>(loss.dx.size()) != steps + 1 || static_cast<int>(loss.dv.size()) != steps + 1) {
    std::ostringstream msg;
    msg << "Backward: the loss gradient must have " << steps + 1 << " entries in dx and dv (got " << loss.dx.size()
        << " and " << loss.dv.size() << ")";
    throw InvalidInputError(msg.str());
  }
  for (int k = 0; k <= steps; ++k) {
    CheckVector(loss.dx[k], n, "loss.dx", true);
    CheckVector(loss.dv[k], n, "loss.dv", true);
  }
  const double h = sim.h();
  const VectorXd& mass = sim.Mass();
  const bool contact = !sim.scene.frictional_contacts.empty() && IsImplicit(sim.options.method);
  RolloutGradient out;
  out.external_force.assign(steps, VectorXd());
  out.activation.assign(steps, VectorXd());
  VectorXd gx = loss.dx[steps].size() ? loss.dx[steps] : VectorXd::Zero(n);
  VectorXd gv = loss.dv[steps].size() ? loss.dv[steps] : VectorXd::Zero(n);
  VectorXd g_memory;  // dL/dm_{i+1} of the controller (empty: zero)
  if (controller) out.controller_parameters = VectorXd::Zero(controller->num_parameters());
  // Material adjoints per part (0: base, r + 1: region r): Lame parameters,
  // and dL/dM (3n), turned into densities at the end (M = sum_p rho_p m_p).
  const int parts = sim.num_parts();
  VectorXd dmu = VectorXd::Zero(parts), dlambda = VectorXd::Zero(parts);
  VectorXd part_mu, part_lambda;
  VectorXd dmass = VectorXd::Zero(n);
  const VectorXd gravity = internal::GravityPerDof(sim);

  // The adjoints solved so far: the next step's initial guess.
  internal::AdjointRecycling recycling(sim.options.adjoint_guess_solutions);
  for (int i = steps - 1; i >= 0; --i) {
    const State& s0 = rollout.states[i];
    const State& s1 = rollout.states[i + 1];
    const internal::ActivationScope activation(sim, rollout.inputs[i].activation);
    VectorXd gx_prev, gv_prev;
    if (IsImplicit(sim.options.method)) {
      VectorXd b = gx + gv / h;
      // With contact the step's active set is held fixed: its nodes are pinned.
      std::optional<internal::ContactPinScope> pins;
      if (contact) pins.emplace(sim, rollout.reports[i].contact_nodes, s1.x);
      internal::StepLinearization lin(sim, s1.x);
      lin.set_recycling(&recycling);
      lin.set_rel_tolerance(internal::AdjointRelTolerance(
          sim.options, rollout.options.rel_tolerance,
          static_cast<int>(rollout.reports.size()) == steps ? &rollout.reports[i] : nullptr));
      const VectorXd z = lin.Solve(b, &out.report);  // zero at fixed DoFs
      sim.elastic.PartLameDots(s1.x, z, sim.part_of_element, parts, &part_mu, &part_lambda, sim.threads());
      dmu -= part_mu;
      dlambda -= part_lambda;
      // grad g depends on M through M (x_{i+1} - x_i - h v_i) / h^2 - M g.
      dmass -= z.cwiseProduct((s1.x - s0.x - h * s0.v) / (h * h) - gravity);
      out.external_force[i] = z;
      if (sim.aux.num_muscles() > 0) out.activation[i] = sim.aux.muscles().ActivationGradient(s1.x, sim.activation, z);
      gx_prev = mass.cwiseProduct(z) / (h * h) - gv / h;
      gv_prev = mass.cwiseProduct(z) / h;
      if (contact) internal::AddPinGradient(sim, lin, s0, rollout.reports[i].contact_nodes, b, z, &gx_prev, &gv_prev);
    } else {
      // Semi-implicit: v1 = v0 + h M^-1 (f - grad E(x0)) on free DoFs, x1 = x0 + h v1.
      VectorXd gvt = gv + h * gx;  // total dL/dv1 through v1 and x1
      sim.ZeroFixed(&gvt);
      const VectorXd w = h * gvt.cwiseQuotient(mass);  // dL/d(force) = h M^-1 gvt
      std::vector<Mat9> dstress;
      sim.elastic.StressDifferentials(s0.x, sim.lame(), &dstress, sim.threads());
      VectorXd hw;
      sim.elastic.ApplyHessian(dstress, w, &hw, sim.threads());
      sim.aux.AddHessianProduct(s0.x, sim.activation, w, &hw);
      if (sim.aux.num_muscles() > 0) out.activation[i] = sim.aux.muscles().ActivationGradient(s0.x, sim.activation, w);
      VectorXd gx_free = gx;
      sim.ZeroFixed(&gx_free);
      gx_prev = gx_free - hw;
      for (int d = 0; d < n; ++d)
        if (sim.fixed[d]) gx_prev(d) -= gv(d) / h;
      gv_prev = gvt;
      sim.elastic.PartLameDots(s0.x, w, sim.part_of_element, parts, &part_mu, &part_lambda, sim.threads());
      dmu -= part_mu;
      dlambda -= part_lambda;
      // M^-1 (f_user + f_state - grad E) varies with M as -M^-2 (...) dM
      // (f_state's explicit dependence on M is added below); gravity's
      // acceleration M^-1 M g does not vary.
      VectorXd grad_e;
      sim.elastic.EnergyAndGradient(s0.x, sim.lame(), &grad_e, sim.threads());
      sim.aux.AddEnergyAndGradient(s0.x, sim.activation, &grad_e);
      VectorXd net = rollout.inputs[i].external_force.size() ? rollout.inputs[i].external_force : VectorXd::Zero(n);
      sim.state_forces.Add(s0.x, s0.v, mass, &net);
      net -= grad_e;
      dmass -= w.cwiseProduct(net).cwiseQuotient(mass);
      out.external_force[i] = w;
    }
    // Explicit state forces f(x_i, v_i; M): dL/df = out.external_force[i].
    sim.state_forces.AddVjp(s0.x, s0.v, mass, out.external_force[i], &gx_prev, &gv_prev, &out.state_forces, &dmass);
    if (controller) {
      // The action u_i = pi(x_i, v_i, m_i): dL/du_i flows into the state and memory.
      const ControlAction g_action{out.activation[i], out.external_force[i]};
      VectorXd g_memory_prev;
      controller->ActVjp(i, s0, rollout.controller_memory[i], g_action, g_memory, &gx_prev, &gv_prev, &g_memory_prev,
                         &out.controller_parameters);
      g_memory = std::move(g_memory_prev);
    }
    if (loss.dx[i].size()) gx_prev += loss.dx[i];
    if (loss.dv[i].size()) gv_prev += loss.dv[i];
    gx = std::move(gx_prev);
    gv = std::move(gv_prev);
  }
  out.x0 = gx;
  out.v0 = gv;
  if (controller) out.controller_memory = g_memory.size() ? g_memory : VectorXd::Zero(controller->memory_size());
  const VectorXd drho = sim.mass_model.DensityGradient(dmass);
  for (int p = 0; p < parts; ++p) {
    double dmu_dE, dmu_dnu, dl_dE, dl_dnu;
    sim.part_material(p).LameDerivatives(&dmu_dE, &dmu_dnu, &dl_dE, &dl_dnu);
    MaterialComponents g;
    g.youngs_modulus = dmu(p) * dmu_dE + dlambda(p) * dl_dE;
    g.poissons_ratio = dmu(p) * dmu_dnu + dlambda(p) * dl_dnu;
    g.density = drho(p);
    if (p == 0) {
      out.youngs_modulus = g.youngs_modulus;
      out.poissons_ratio = g.poissons_ratio;
      out.density = g.density;
    } else {
      out.region_materials.push_back(g);
    }
  }
  bool finite = out.x0.allFinite() && out.v0.allFinite() && std::isfinite(out.youngs_modulus) &&
                std::isfinite(out.poissons_ratio) && std::isfinite(out.density);
  for (int i = 0; i < steps; ++i) finite = finite && out.external_force[i].allFinite() && out.activation[i].allFinite();
  for (const MaterialComponents& g : out.region_materials)
    finite = finite && std::isfinite(g.youngs_modulus) && std::isfinite(g.poissons_ratio) && std::isfinite(g.density);
  if (!finite) throw SolverError(SolverStatus::kNonFinite, "the gradient is not finite");
  out.report.seconds = Seconds(start);
  return out;
}

}  // namespace

RolloutGradient Simulator::Backward(const Rollout& rollout, const LossGradient& loss) {
  return CheckedBackward(rollout, loss, nullptr);
}

RolloutGradient Simulator::Backward(const Rollout& rollout, const LossGradient& loss, const Controller& controller) {
  if (!rollout.closed_loop()) throw InvalidInputError("Backward: the rollout is open-loop (made without a controller)");
  if (static_cast<int>(rollout.controller_memory.size()) != rollout.num_steps() + 1)
    throw InvalidInputError("Backward: the rollout has inconsistent controller memory and inputs");
  const VectorXd theta = controller.parameters();
  if (theta.size() != rollout.controller_parameters.size() || theta != rollout.controller_parameters)
    throw InvalidInputError("Backward: the controller's parameters differ from those the rollout was made with");
  for (const VectorXd& m : rollout.controller_memory)
    if (m.size() != controller.memory_size()) {
      std::ostringstream msg;
      msg << "Backward: the rollout's controller memory has " << m.size() << " entries, the controller's "
          << controller.memory_size();
      throw InvalidInputError(msg.str());
    }
  return CheckedBackward(rollout, loss, &controller);
}

RolloutGradient Simulator::CheckedBackward(const Rollout& rollout, const LossGradient& loss,
                                           const Controller* controller) {
  internal::CheckRolloutForDerivatives(*impl_, rollout, "Backward");
  // The rollout is finite: a non-finite value on the way is an overflow.
  try {
    return BackwardPass(*impl_, rollout, loss, controller);
  } catch (const SolverError& e) {
    if (e.status() != SolverStatus::kNonFinite) throw;
    throw SolverError(SolverStatus::kNonFinite, std::string(ToString(impl_->options.method)) +
                                                    " backward: the adjoint overflowed double precision (" + e.what() +
                                                    ")");
  }
}

VectorXd Simulator::SolveQuasiStatic(const VectorXd& initial_positions, const StepInput& input, StepReport* report) {
  SimulatorImpl& sim = *impl_;
  const int n = sim.num_dofs();
  CheckVector(initial_positions, n, "initial_positions", false);
  CheckVector(input.external_force, n, "external_force", true);
  internal::CheckActivation(input.activation, sim.aux.num_muscles());
  const internal::ActivationScope activation(sim, input.activation);
  StepReport local;
  StepReport* rep = report ? report : &local;
  *rep = StepReport();
  const Method saved = sim.options.method;
  if (saved != Method::kNewtonPcg) sim.options.method = Method::kNewtonCholesky;
  VectorXd x0 = initial_positions;
  for (int d = 0; d < n; ++d)
    if (sim.fixed[d]) x0(d) = sim.fixed_values(d);
  internal::StepObjective objective(sim, VectorXd::Zero(n), sim.ExplicitForce(input), /*static_problem=*/true);
  try {
    VectorXd x = internal::NewtonSolve(objective, x0, rep);
    sim.options.method = saved;
    return x;
  } catch (...) {
    sim.options.method = saved;
    throw;
  }
}

}  // namespace diffpd
