#include "diffpd/simulator.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>

#include "contact/active_set_step.h"
#include "diffpd/error.h"
#include "forces/activation_scope.h"
#include "forces/quad_hydrodynamic_force.h"
#include "solver/adjoint_sweep.h"
#include "solver/energy_bounded_step.h"
#include "solver/explicit_stability.h"
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

// Rest positions: the mesh's, Dirichlet DoFs at their prescribed values.
VectorXd RestPositions(const SimulatorImpl& sim) {
  VectorXd x = Eigen::Map<const VectorXd>(sim.scene.mesh.vertices.data(), sim.num_dofs());
  for (size_t k = 0; k < sim.scene.dirichlet.dofs.size(); ++k)
    x(sim.scene.dirichlet.dofs[k]) = sim.scene.dirichlet.values(k);
  return x;
}

// The end of a divergence message: the time step and, for an explicit
// method, how it compares with the stability limit at the rest shape.
std::string StepAdvice(SimulatorImpl& sim) {
  std::ostringstream msg;
  msg << "h = " << sim.h() << " s";
  if (IsImplicit(sim.options.method)) return msg.str();
  const double limit = internal::ExplicitStableTimeStep(sim, RestPositions(sim));
  if (sim.h() > limit)
    msg << ", above semi-implicit Euler's stability limit at the rest shape, about " << limit << " s";
  else
    msg << ", within semi-implicit Euler's stability limit at the rest shape, about " << limit
        << " s, which deformation, damping and the state forces lower";
  msg << ": use a smaller time step or an implicit method";
  return msg.str();
}

// SolverOptions::max_extent_ratio: throws SolverError(kDiverged) when the
// nodes' bounding box at positions x is too large.
void CheckExtent(SimulatorImpl& sim, const VectorXd& x) {
  const double bound = sim.options.max_extent_ratio * sim.rest_extent;
  if (std::isinf(bound)) return;
  const Eigen::Map<const Eigen::Matrix3Xd> nodes(x.data(), 3, x.size() / 3);
  const double extent = (nodes.rowwise().maxCoeff() - nodes.rowwise().minCoeff()).norm();
  if (extent <= bound) return;
  std::ostringstream msg;
  msg << ToString(sim.options.method) << ": the step diverged: the body's extent (its bounding box's diagonal) grew to "
      << extent << " m, beyond max_extent_ratio = " << sim.options.max_extent_ratio << " times its rest extent "
      << sim.rest_extent << " m (" << StepAdvice(sim) << ")";
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
  s.x = RestPositions(*impl_);
  s.v = VectorXd::Zero(impl_->num_dofs());
  return s;
}

VectorXd Simulator::LumpedMass() const { return impl_->Mass(); }

double Simulator::ElasticEnergy(const VectorXd& x) {
  CheckVector(x, impl_->num_dofs(), "positions", false);
  return impl_->elastic.EnergyAndGradient(x, impl_->lame(), nullptr, impl_->threads());
}

double Simulator::ExplicitStableTimeStep(const VectorXd& x, const VectorXd& activation) {
  try {
    CheckVector(x, impl_->num_dofs(), "x", false);
    internal::CheckActivation(activation, impl_->aux.num_muscles());
  } catch (const InvalidInputError& e) {
    throw InvalidInputError(std::string("ExplicitStableTimeStep: ") + e.what());
  }
  const internal::ActivationScope scope(*impl_, activation);
  return internal::ExplicitStableTimeStep(*impl_, x);
}

int Simulator::num_pd_factorizations() const {
  // The PD system exists only once a PD method has stepped.
  return impl_->pd_factorizations();
}

double Simulator::pd_factorization_seconds() const { return impl_->pd_factorization_seconds(); }

std::size_t Simulator::pd_factor_copy_bytes() const { return impl_->pd_factor_copy_bytes(); }

State Simulator::Step(const State& state, const StepInput& input, StepReport* report) {
  SimulatorImpl& sim = *impl_;
  const int n = sim.num_dofs();
  CheckVector(state.x, n, "state.x", false);
  CheckVector(state.v, n, "state.v", false);
  CheckVector(input.external_force, n, "external_force", true);
  internal::CheckActivation(input.activation, sim.aux.num_muscles());
  internal::CheckWettedQuads(input.wetted_quads, sim.scene.quad_hydrodynamics);
  const internal::ActivationScope activation(sim, input.activation);
  const auto start = Clock::now();
  // Cold SVDs: the step's result depends on (state, input) alone.
  if (!sim.options.svd_warm_start) sim.elastic.ResetWarmStart();
  StepReport local;
  StepReport* rep = report ? report : &local;
  *rep = StepReport();
  const double h = sim.h();
  VectorXd f = sim.ExplicitForce(input);
  sim.state_forces.Add(state.x, state.v, sim.Mass(), input.wetted_quads, &f);
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
    msg << ToString(sim.options.method) << ": the state became non-finite (" << StepAdvice(sim) << ")";
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
      internal::CheckWettedQuads(inputs[i].wetted_quads, impl_->scene.quad_hydrodynamics);
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
  internal::CheckLossGradient(loss, steps, n);
  const bool with_reports = static_cast<int>(rollout.reports.size()) == steps;
  internal::AdjointSweep sweep(sim, steps, rollout.options, loss.dx[steps], loss.dv[steps], controller);
  for (int i = steps - 1; i >= 0; --i)
    sweep.Step(i, rollout.states[i], rollout.states[i + 1], rollout.inputs[i],
               with_reports ? &rollout.reports[i] : nullptr, controller ? &rollout.controller_memory[i] : nullptr,
               loss.dx[i], loss.dv[i]);
  RolloutGradient out = sweep.Finish();
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
