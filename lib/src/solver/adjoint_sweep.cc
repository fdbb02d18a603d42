#include "solver/adjoint_sweep.h"

#include <cmath>
#include <optional>

#include "contact/active_set_step.h"
#include "diffpd/error.h"
#include "forces/activation_scope.h"
#include "solver/adjoint_tolerance.h"

namespace diffpd::internal {

AdjointSweep::AdjointSweep(SimulatorImpl& sim, int steps, const SolverOptions& forward_options, const VectorXd& dx_last,
                           const VectorXd& dv_last, const Controller* controller, bool keep_step_gradients)
    : sim_(sim),
      forward_rel_tolerance_(forward_options.rel_tolerance),
      svd_warm_start_(forward_options.svd_warm_start),
      controller_(controller),
      keep_(keep_step_gradients),
      recycling_(sim.options.adjoint_guess_solutions) {
  const int n = sim.num_dofs();
  if (keep_) {
    out_.external_force.assign(steps, VectorXd());
    out_.activation.assign(steps, VectorXd());
  }
  gx_ = dx_last.size() ? dx_last : VectorXd::Zero(n);
  gv_ = dv_last.size() ? dv_last : VectorXd::Zero(n);
  if (controller) out_.controller_parameters = VectorXd::Zero(controller->num_parameters());
  const int parts = sim.num_parts();
  dmu_ = VectorXd::Zero(parts);
  dlambda_ = VectorXd::Zero(parts);
  dmass_ = VectorXd::Zero(n);
  gravity_ = GravityPerDof(sim);
}

void AdjointSweep::Step(int i, const State& s0, const State& s1, const StepInput& input, const StepReport* report,
                        const VectorXd* memory, const VectorXd& dx_i, const VectorXd& dv_i) {
  SimulatorImpl& sim = sim_;
  const int n = sim.num_dofs();
  const double h = sim.h();
  const VectorXd& mass = sim.Mass();
  const int parts = sim.num_parts();
  const bool implicit = sim.options.method != Method::kSemiImplicit;
  const bool contact = !sim.scene.frictional_contacts.empty() && implicit;
  const ActivationScope activation(sim, input.activation);
  // Cold SVDs where the forward had them: the step's gradient depends on its
  // states alone, not on what was evaluated before (a checkpointed backward
  // recomputes steps in between).
  if (!svd_warm_start_) sim.elastic.ResetWarmStart();
  VectorXd part_mu, part_lambda;
  VectorXd gx_prev, gv_prev;
  activation_.resize(0);
  if (implicit) {
    VectorXd b = gx_ + gv_ / h;
    // With contact the step's active set is held fixed: its nodes are pinned.
    std::optional<ContactPinScope> pins;
    if (contact) pins.emplace(sim, report->contact_nodes, s1.x);
    StepLinearization lin(sim, s1.x);
    lin.set_recycling(&recycling_);
    lin.set_steps_left(i + 1);  // steps i, i - 1, ..., 0
    lin.set_rel_tolerance(AdjointRelTolerance(sim.options, forward_rel_tolerance_, report));
    // The Lame-parameter dots below reuse the SVDs of H's element pass. They
    // start cold: H then depends on x alone, as the tangent pass's H does
    // (warm-started SVDs moved an ill-conditioned scene's gradient off its
    // tangents by 1.4e-4 relative).
    lin.KeepLameGradients();
    VectorXd z = lin.Solve(b, &out_.report);  // zero at fixed DoFs
    lin.PartLameDots(z, &part_mu, &part_lambda);
    dmu_ -= part_mu;
    dlambda_ -= part_lambda;
    // grad g depends on M through M (x_{i+1} - x_i - h v_i) / h^2 - M g.
    dmass_ -= z.cwiseProduct((s1.x - s0.x - h * s0.v) / (h * h) - gravity_);
    if (sim.aux.num_muscles() > 0) activation_ = sim.aux.muscles().ActivationGradient(s1.x, sim.activation, z);
    gx_prev = mass.cwiseProduct(z) / (h * h) - gv_ / h;
    gv_prev = mass.cwiseProduct(z) / h;
    if (contact) AddPinGradient(sim, lin, s0, report->contact_nodes, b, z, &gx_prev, &gv_prev);
    external_force_ = std::move(z);
  } else {
    // Semi-implicit: v1 = v0 + h M^-1 (f - grad E(x0)) on free DoFs, x1 = x0 + h v1.
    VectorXd gvt = gv_ + h * gx_;  // total dL/dv1 through v1 and x1
    sim.ZeroFixed(&gvt);
    VectorXd w = h * gvt.cwiseQuotient(mass);  // dL/d(force) = h M^-1 gvt
    std::vector<Mat9> dstress;
    sim.elastic.StressDifferentials(s0.x, sim.lame(), &dstress, sim.threads());
    VectorXd hw;
    sim.elastic.ApplyHessian(dstress, w, &hw, sim.threads());
    sim.aux.AddHessianProduct(s0.x, sim.activation, w, &hw);
    if (sim.aux.num_muscles() > 0) activation_ = sim.aux.muscles().ActivationGradient(s0.x, sim.activation, w);
    VectorXd gx_free = gx_;
    sim.ZeroFixed(&gx_free);
    gx_prev = gx_free - hw;
    for (int d = 0; d < n; ++d)
      if (sim.fixed[d]) gx_prev(d) -= gv_(d) / h;
    gv_prev = gvt;
    sim.elastic.PartLameDots(s0.x, w, sim.part_of_element, parts, &part_mu, &part_lambda, sim.threads());
    dmu_ -= part_mu;
    dlambda_ -= part_lambda;
    // M^-1 (f_user + f_state - grad E) varies with M as -M^-2 (...) dM
    // (f_state's explicit dependence on M is added below); gravity's
    // acceleration M^-1 M g does not vary.
    VectorXd grad_e;
    sim.elastic.EnergyAndGradient(s0.x, sim.lame(), &grad_e, sim.threads());
    sim.aux.AddEnergyAndGradient(s0.x, sim.activation, &grad_e);
    VectorXd net = input.external_force.size() ? input.external_force : VectorXd::Zero(n);
    sim.state_forces.Add(s0.x, s0.v, mass, input.wetted_quads, &net);
    net -= grad_e;
    dmass_ -= w.cwiseProduct(net).cwiseQuotient(mass);
    external_force_ = std::move(w);
  }
  // Explicit state forces f(x_i, v_i; M): dL/df = external_force_.
  sim.state_forces.AddVjp(s0.x, s0.v, mass, input.wetted_quads, external_force_, &gx_prev, &gv_prev, &out_.state_forces,
                          &dmass_);
  if (controller_) {
    // The action u_i = pi(x_i, v_i, m_i): dL/du_i flows into the state and memory.
    const ControlAction g_action{activation_, external_force_};
    VectorXd g_memory_prev;
    controller_->ActVjp(i, s0, *memory, g_action, g_memory_, &gx_prev, &gv_prev, &g_memory_prev,
                        &out_.controller_parameters);
    g_memory_ = std::move(g_memory_prev);
  }
  if (dx_i.size()) gx_prev += dx_i;
  if (dv_i.size()) gv_prev += dv_i;
  gx_ = std::move(gx_prev);
  gv_ = std::move(gv_prev);
  finite_steps_ = finite_steps_ && external_force_.allFinite() && activation_.allFinite();
  if (keep_) {
    out_.external_force[i] = external_force_;
    out_.activation[i] = activation_;
  }
}

RolloutGradient AdjointSweep::Finish() {
  SimulatorImpl& sim = sim_;
  RolloutGradient out = std::move(out_);
  out.x0 = gx_;
  out.v0 = gv_;
  if (controller_) out.controller_memory = g_memory_.size() ? g_memory_ : VectorXd::Zero(controller_->memory_size());
  const VectorXd drho = sim.mass_model.DensityGradient(dmass_);
  for (int p = 0; p < sim.num_parts(); ++p) {
    double dmu_dE, dmu_dnu, dl_dE, dl_dnu;
    sim.part_material(p).LameDerivatives(&dmu_dE, &dmu_dnu, &dl_dE, &dl_dnu);
    MaterialComponents g;
    g.youngs_modulus = dmu_(p) * dmu_dE + dlambda_(p) * dl_dE;
    g.poissons_ratio = dmu_(p) * dmu_dnu + dlambda_(p) * dl_dnu;
    g.density = drho(p);
    if (p == 0) {
      out.youngs_modulus = g.youngs_modulus;
      out.poissons_ratio = g.poissons_ratio;
      out.density = g.density;
    } else {
      out.region_materials.push_back(g);
    }
  }
  bool finite = finite_steps_ && out.x0.allFinite() && out.v0.allFinite() && std::isfinite(out.youngs_modulus) &&
                std::isfinite(out.poissons_ratio) && std::isfinite(out.density);
  for (const MaterialComponents& g : out.region_materials)
    finite = finite && std::isfinite(g.youngs_modulus) && std::isfinite(g.poissons_ratio) && std::isfinite(g.density);
  if (!finite) throw SolverError(SolverStatus::kNonFinite, "the gradient is not finite");
  return out;
}

}  // namespace diffpd::internal
