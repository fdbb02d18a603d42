#include "solver/simulator_impl.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::internal {

SimulatorImpl::SimulatorImpl(const Scene& scene_in, const SolverOptions& options_in)
    : scene((scene_in.Validate(), scene_in)),
      options((options_in.Validate(), options_in)),
      fem(scene.mesh),
      elastic(fem, scene.energies),
      aux(fem, scene),
      state_forces(scene, fem.unit_lumped_mass()) {
  const int n = scene.mesh.num_dofs();
  fixed.assign(n, 0);
  fixed_values = VectorXd::Zero(n);
  for (size_t k = 0; k < scene.dirichlet.dofs.size(); ++k) {
    fixed[scene.dirichlet.dofs[k]] = 1;
    fixed_values(scene.dirichlet.dofs[k]) = scene.dirichlet.values(k);
  }
  unit_mass.resize(n);
  for (int i = 0; i < fem.num_nodes(); ++i) unit_mass.segment<3>(3 * i).setConstant(fem.unit_lumped_mass()(i));
}

VectorXd SimulatorImpl::ExplicitForce(const StepInput& input) const {
  const int n = num_dofs();
  VectorXd f = VectorXd::Zero(n);
  if (scene.gravity) {
    for (int i = 0; i < n / 3; ++i) f.segment<3>(3 * i) = rho() * unit_mass(3 * i) * (*scene.gravity);
  }
  if (input.external_force.size() > 0) f += input.external_force;
  return f;
}

void SimulatorImpl::ZeroFixed(VectorXd* v) const {
  for (int d = 0; d < v->size(); ++d)
    if (fixed[d]) (*v)(d) = 0.0;
}

HessianAssembler& SimulatorImpl::hessian_assembler() {
  if (!hessian_) hessian_ = std::make_unique<HessianAssembler>(scene.mesh);
  return *hessian_;
}

PdSystem& SimulatorImpl::pd_system() {
  if (!pd_) {
    pd_ = std::make_unique<PdSystem>(fem, fixed);
    if (!aux.empty()) pd_->SetAuxiliaryMatrix(aux.PdMatrix());
  }
  // PD-LBFGS preconditions with a softer A (SolverOptions::lbfgs_weight_scale).
  const double scale = options.method == Method::kPdLbfgs ? options.lbfgs_weight_scale : 1.0;
  pd_->Update(h(), rho(), scale * elastic.PdWeight(mu(), lambda()));
  return *pd_;
}

StepObjective::StepObjective(SimulatorImpl& sim, VectorXd xhat, VectorXd force, bool static_problem)
    : sim_(sim), xhat_(std::move(xhat)), force_(std::move(force)) {
  inertia_ = static_problem ? VectorXd::Zero(sim.num_dofs()) : VectorXd(sim.Mass() / (sim.h() * sim.h()));
}

double StepObjective::Evaluate(const VectorXd& x, VectorXd* grad) {
  const double e = sim_.elastic.EnergyAndGradient(x, sim_.mu(), sim_.lambda(), grad, sim_.threads());
  const VectorXd dx = x - xhat_;
  double value = e + sim_.aux.AddEnergyAndGradient(x, sim_.activation, grad);
  for (int d = 0; d < x.size(); ++d) {
    if (sim_.fixed[d]) continue;
    value += 0.5 * inertia_(d) * dx(d) * dx(d) - force_(d) * x(d);
  }
  if (grad) {
    grad->array() += inertia_.array() * dx.array() - force_.array();
    sim_.ZeroFixed(grad);
    CheckFinite(*grad, "grad g");
  }
  if (!std::isfinite(value)) throw SolverError(SolverStatus::kNonFinite, "the step objective g(x) is not finite");
  return value;
}

bool Converged(const SolverOptions& options, double grad_norm, double initial_norm) {
  return grad_norm <= options.abs_tolerance + options.rel_tolerance * initial_norm;
}

bool IterationConverged(const SolverOptions& options, int it, double grad_norm, StepReport* report) {
  report->iterations = it;
  report->final_residual = grad_norm;
  if (options.verbosity >= 2)
    std::fprintf(stderr, "  %s iteration %d |grad g| = %.3e\n", ToString(options.method), it, grad_norm);
  if (Converged(options, grad_norm, report->initial_residual)) return true;
  if (it >= options.max_iterations) ThrowNotConverged(options, it, grad_norm, report->initial_residual);
  return false;
}

void ThrowNotConverged(const SolverOptions& options, int iterations, double grad_norm, double initial_norm) {
  std::ostringstream msg;
  msg << ToString(options.method) << ": the step did not converge in " << iterations
      << " iterations (|grad g| = " << grad_norm << ", initial " << initial_norm << ", tolerance "
      << options.abs_tolerance + options.rel_tolerance * initial_norm << ")";
  throw SolverError(SolverStatus::kMaxIterations, msg.str());
}

void CheckFinite(const VectorXd& v, const char* what) {
  if (!v.allFinite()) throw SolverError(SolverStatus::kNonFinite, std::string(what) + " is not finite");
}

}  // namespace diffpd::internal
