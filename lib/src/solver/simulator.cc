#include "diffpd/simulator.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "contact/active_set_step.h"
#include "diffpd/error.h"
#include "forces/activation_scope.h"
#include "solver/simulator_impl.h"

namespace diffpd {
namespace {

using internal::SimulatorImpl;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

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
}

void Simulator::SetMaterial(const MaterialParameters& material) {
  material.Validate();
  impl_->scene.material = material;
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
  return impl_->elastic.EnergyAndGradient(x, impl_->mu(), impl_->lambda(), nullptr, impl_->threads());
}

int Simulator::num_pd_factorizations() const {
  // The PD system exists only once a PD method has stepped.
  return impl_->pd_factorizations();
}

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
  sim.state_forces.Add(state.x, state.v, sim.rho(), &f);
  State next;
  if (sim.options.method == Method::kSemiImplicit) {
    if (!sim.scene.frictional_contacts.empty())
      throw InvalidInputError("semi-implicit: frictional contact needs an implicit method (newton-cholesky, "
                              "newton-pcg, pd, pd-lbfgs); use penalty contact instead");
    VectorXd grad;
    sim.elastic.EnergyAndGradient(state.x, sim.mu(), sim.lambda(), &grad, sim.threads());
    sim.aux.AddEnergyAndGradient(state.x, sim.activation, &grad);
    next.v = state.v + h * ((f - grad).array() / sim.Mass().array()).matrix();
    next.x = state.x + h * next.v;
  } else {
    const internal::ImplicitSolver solve = [&sim](internal::StepObjective& objective, const VectorXd& x0,
                                                  StepReport* r) -> VectorXd {
      switch (sim.options.method) {
        case Method::kNewtonCholesky:
        case Method::kNewtonPcg: return internal::NewtonSolve(objective, x0, r);
        case Method::kPd: return internal::PdSolve(objective, x0, r);
        case Method::kPdLbfgs: return internal::PdLbfgsSolve(objective, x0, r);
        case Method::kSemiImplicit: break;
      }
      return x0;
    };
    if (!sim.scene.frictional_contacts.empty()) {
      next.x = internal::SolveWithActiveSet(sim, state, f, solve, rep);
    } else {
      VectorXd x0 = state.x + h * state.v;
      for (int d = 0; d < n; ++d)
        if (sim.fixed[d]) x0(d) = sim.fixed_values(d);
      internal::StepObjective objective(sim, state.x + h * state.v, f);
      next.x = solve(objective, x0, rep);
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
  rep->seconds = Seconds(start);
  if (sim.options.verbosity >= 1)
    std::fprintf(stderr, "%s step: %d iterations, |grad g| %.3e -> %.3e, %.4f s\n", ToString(sim.options.method),
                 rep->iterations, rep->initial_residual, rep->final_residual, rep->seconds);
  return next;
}

Rollout Simulator::Simulate(const State& initial, const std::vector<StepInput>& inputs) {
  Rollout r;
  r.material = impl_->scene.material;
  r.options = impl_->options;
  r.inputs = inputs;
  r.states.reserve(inputs.size() + 1);
  r.reports.resize(inputs.size());
  r.states.push_back(initial);
  for (size_t i = 0; i < inputs.size(); ++i) r.states.push_back(Step(r.states.back(), inputs[i], &r.reports[i]));
  return r;
}

RolloutGradient Simulator::Backward(const Rollout& rollout, const LossGradient& loss) {
  SimulatorImpl& sim = *impl_;
  const auto start = Clock::now();
  const int n = sim.num_dofs();
  const int steps = rollout.num_steps();
  if (static_cast<int>(rollout.states.size()) != steps + 1)
    throw InvalidInputError("Backward: the rollout has inconsistent states and inputs");
  if (static_cast<int>(loss.dx.size()) != steps + 1 || static_cast<int>(loss.dv.size()) != steps + 1) {
    std::ostringstream msg;
    msg << "Backward: the loss gradient must have " << steps + 1 << " entries in dx and dv (got " << loss.dx.size()
        << " and " << loss.dv.size() << ")";
    throw InvalidInputError(msg.str());
  }
  const MaterialParameters& mat = sim.scene.material;
  if (rollout.material.youngs_modulus != mat.youngs_modulus || rollout.material.poissons_ratio != mat.poissons_ratio ||
      rollout.material.density != mat.density || rollout.options.time_step != sim.h() ||
      rollout.options.method != sim.options.method)
    throw InvalidInputError(
        "Backward: the rollout was made with another material, time step or method than the simulator's current ones");
  for (int k = 0; k <= steps; ++k) {
    CheckVector(loss.dx[k], n, "loss.dx", true);
    CheckVector(loss.dv[k], n, "loss.dv", true);
  }
  const double h = sim.h();
  const VectorXd mass = sim.Mass();
  const bool contact = !sim.scene.frictional_contacts.empty() && IsImplicit(sim.options.method);
  if (contact && static_cast<int>(rollout.reports.size()) != steps)
    throw InvalidInputError("Backward: a rollout with frictional contact needs its step reports (active sets)");
  RolloutGradient out;
  out.external_force.assign(steps, VectorXd());
  out.activation.assign(steps, VectorXd());
  VectorXd gx = loss.dx[steps].size() ? loss.dx[steps] : VectorXd::Zero(n);
  VectorXd gv = loss.dv[steps].size() ? loss.dv[steps] : VectorXd::Zero(n);
  double dmu = 0, dlambda = 0, drho = 0;
  VectorXd grad_mu, grad_lambda;
  VectorXd gravity_unit = VectorXd::Zero(n);
  if (sim.scene.gravity)
    for (int i = 0; i < n / 3; ++i) gravity_unit.segment<3>(3 * i) = sim.unit_mass(3 * i) * (*sim.scene.gravity);

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
      const VectorXd z = lin.Solve(b, &out.report);  // zero at fixed DoFs
      sim.elastic.EnergyAndGradient(s1.x, 1.0, 0.0, &grad_mu, sim.threads());
      sim.elastic.EnergyAndGradient(s1.x, 0.0, 1.0, &grad_lambda, sim.threads());
      dmu -= z.dot(grad_mu);
      dlambda -= z.dot(grad_lambda);
      const VectorXd dgrad_drho =
          sim.unit_mass.cwiseProduct(s1.x - s0.x - h * s0.v) / (h * h) - gravity_unit;
      drho -= z.dot(dgrad_drho);
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
      sim.elastic.StressDifferentials(s0.x, sim.mu(), sim.lambda(), &dstress, sim.threads());
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
      sim.elastic.EnergyAndGradient(s0.x, 1.0, 0.0, &grad_mu, sim.threads());
      sim.elastic.EnergyAndGradient(s0.x, 0.0, 1.0, &grad_lambda, sim.threads());
      dmu -= w.dot(grad_mu);
      dlambda -= w.dot(grad_lambda);
      // M^-1 (f_user - grad E) scales as 1/rho; gravity's acceleration does not.
      VectorXd grad_e;
      sim.elastic.EnergyAndGradient(s0.x, sim.mu(), sim.lambda(), &grad_e, sim.threads());
      sim.aux.AddEnergyAndGradient(s0.x, sim.activation, &grad_e);
      VectorXd user = rollout.inputs[i].external_force.size() ? rollout.inputs[i].external_force : VectorXd::Zero(n);
      sim.state_forces.Add(s0.x, s0.v, sim.rho(), &user);  // M^-1 f scales as 1/rho for these too
      drho -= w.dot(user - grad_e) / sim.rho();
      out.external_force[i] = w;
    }
    // Explicit state forces f(x_i, v_i): dL/df = out.external_force[i].
    drho += sim.state_forces.AddVjp(s0.x, s0.v, sim.rho(), out.external_force[i], &gx_prev, &gv_prev,
                                    &out.state_forces);
    if (loss.dx[i].size()) gx_prev += loss.dx[i];
    if (loss.dv[i].size()) gv_prev += loss.dv[i];
    gx = std::move(gx_prev);
    gv = std::move(gv_prev);
  }
  out.x0 = gx;
  out.v0 = gv;
  double dmu_dE, dmu_dnu, dl_dE, dl_dnu;
  mat.LameDerivatives(&dmu_dE, &dmu_dnu, &dl_dE, &dl_dnu);
  out.youngs_modulus = dmu * dmu_dE + dlambda * dl_dE;
  out.poissons_ratio = dmu * dmu_dnu + dlambda * dl_dnu;
  out.density = drho;
  out.report.seconds = Seconds(start);
  return out;
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
