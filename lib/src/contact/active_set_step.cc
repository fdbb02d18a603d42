#include "contact/active_set_step.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "diffpd/error.h"
#include "solver/energy_bounded_step.h"

namespace diffpd::internal {
namespace {

// A node with gap <= kTouch is on the surface (resting contact).
constexpr double kTouch = 1e-9;  // m

struct Candidate {
  int node;
  const ContactSurface* surface;
};

std::vector<Candidate> Candidates(const Scene& scene) {
  std::vector<Candidate> out;
  for (const FrictionalContact& c : scene.frictional_contacts)
    for (const int i : c.nodes) out.push_back(Candidate{i, &c.surface});
  return out;
}

// For its lifetime: an absolute step tolerance `target` (if > 0), else the
// options' own.
class ToleranceScope {
 public:
  ToleranceScope(SimulatorImpl& sim, double target)
      : sim_(sim), abs_(sim.options.abs_tolerance), rel_(sim.options.rel_tolerance) {
    if (target <= 0) return;
    sim.options.abs_tolerance = target;
    sim.options.rel_tolerance = 0;
  }
  ~ToleranceScope() {
    sim_.options.abs_tolerance = abs_;
    sim_.options.rel_tolerance = rel_;
  }

 private:
  SimulatorImpl& sim_;
  double abs_, rel_;
};

// Throws SolverError(kContactEnergyGain) when the step from `state` to x
// (with pinned nodes) raised the total energy beyond what
// FrictionalContactOptions::max_energy_gain allows (diffpd/contact.h).
void CheckContactEnergy(SimulatorImpl& sim, const State& state, const VectorXd& xhat, const VectorXd& force,
                        const VectorXd& x, double residual) {
  const double allowed_ratio = sim.scene.frictional_contact_options.max_energy_gain;
  if (std::isinf(allowed_ratio)) return;
  const double h = sim.h();
  const VectorXd& mass = sim.Mass();
  const VectorXd v1 = (x - state.x) / h;
  const double k0 = 0.5 * state.v.cwiseProduct(mass).dot(state.v);
  const double k1 = 0.5 * v1.cwiseProduct(mass).dot(v1);
  // g with the inertia centred on x_i is 1/2 |v_i+1|_M^2 + E(x) - f . x at x;
  // centred on x_i + h v_i, at x_i, the previous total 1/2 |v_i|_M^2 + E(x_i) - f . x_i.
  StepObjective at_rest(sim, state.x, force);
  StepObjective predicted(sim, xhat, force);
  const double t1 = at_rest.Evaluate(x, nullptr);
  const double t0 = predicted.Evaluate(state.x, nullptr);
  const double e0 = sim.elastic.EnergyAndGradient(state.x, sim.lame(), nullptr, sim.threads());
  const double e1 = sim.elastic.EnergyAndGradient(x, sim.lame(), nullptr, sim.threads());
  const double involved = k0 + k1 + std::abs(e0) + std::abs(e1) + std::abs(force.dot(x - state.x));
  const double allowed = allowed_ratio * involved + residual * (x - state.x).norm();
  if (!(t1 - t0 > allowed)) return;
  std::ostringstream msg;
  msg << "frictional contact: the step raised the total energy from " << t0 << " J to " << t1 << " J (by "
      << (t1 - t0) / involved << " of the " << involved
      << " J involved; frictional_contact_options.max_energy_gain = " << allowed_ratio
      << "): nodes are pinned where their previous positions project onto the surface, too far from where this "
         "step would put them for the body's cells and stiffness; a smaller time step resolves the contact";
  throw SolverError(SolverStatus::kContactEnergyGain, msg.str());
}

}  // namespace

ContactPin ComputeContactPin(const ContactSurface& surface, const Vec3& x, const Vec3& /*v*/, double /*h*/) {
  return ContactPin{surface.Project(x), surface.ProjectJacobian(x), Mat3::Zero()};
}

VectorXd SolveWithActiveSet(SimulatorImpl& sim, const State& state, const VectorXd& force, const ImplicitSolver& solve,
                            StepReport* report) {
  const FrictionalContactOptions& opt = sim.scene.frictional_contact_options;
  const double h = sim.h();
  const int n = sim.num_dofs();
  const VectorXd xhat = state.x + h * state.v;
  const std::vector<Candidate> cand = Candidates(sim.scene);
  const int nc = static_cast<int>(cand.size());
  // released/locked: anti-cycling of refining passes; screen_released: nodes
  // released on a loose (screening) solve, which never lock anything.
  std::vector<char> active(nc, 0), released(nc, 0), locked(nc, 0), screen_released(nc, 0);
  std::vector<ContactPin> pins(nc);
  std::vector<char> have_pin(nc, 0);
  auto pin_of = [&](int c) -> const ContactPin& {
    if (!have_pin[c]) {
      const int i = cand[c].node;
      pins[c] = ComputeContactPin(*cand[c].surface, state.x.segment<3>(3 * i), state.v.segment<3>(3 * i), h);
      have_pin[c] = 1;
    }
    return pins[c];
  };
  for (int c = 0; c < nc; ++c) active[c] = cand[c].surface->Gap(xhat.segment<3>(3 * cand[c].node)) <= kTouch;

  // Applies the complementarity test at x (grad: grad g with the pinned rows
  // kept, i.e. the contact forces there) to the set: releases pinned nodes
  // pulled into the surface, adds free candidates below it. Returns whether
  // the set changed; sets *cycled when a node released on a loose solve
  // comes back on one.
  auto update_set = [&](const VectorXd& xs, const VectorXd& grad, bool screening_pass, bool* cycled) {
    bool changed = false;
    for (int c = 0; c < nc; ++c) {
      const int i = cand[c].node;
      if (active[c]) {
        const Vec3 normal = cand[c].surface->GapGradient(pin_of(c).position);
        if (!locked[c] && normal.dot(grad.segment<3>(3 * i)) < 0) {
          active[c] = 0;
          (screening_pass ? screen_released : released)[c] = 1;
          changed = true;
        }
      } else if (cand[c].surface->Gap(xs.segment<3>(3 * i)) < -opt.penetration_tolerance) {
        active[c] = 1;
        // Only converged passes lock a node (the lock makes the final set
        // depend on the path; loose solves must not choose it). A node back
        // in on a loose solve ends screening instead.
        if (screening_pass)
          *cycled = *cycled || screen_released[c];
        else if (released[c])
          locked[c] = 1;
        changed = true;
      }
    }
    return changed;
  };

  VectorXd x = xhat;
  // Screening (contact.h): while `screening`, each pass's solve pauses at a
  // checkpoint at the loose tolerance and ends there if the set changes; if
  // it does not, the same solve goes on to the step's tolerance (no restart)
  // and screening ends.
  bool screening = opt.screening_rel_tolerance > sim.options.rel_tolerance;
  double first_target = 0, screen_target = 0;
  for (int pass = 1;; ++pass) {
    // Active nodes in increasing order, with their pins.
    std::vector<std::pair<int, int>> order;  // (node, candidate)
    for (int c = 0; c < nc; ++c)
      if (active[c]) order.emplace_back(cand[c].node, c);
    std::sort(order.begin(), order.end());
    std::vector<int> nodes;
    VectorXd pinned = VectorXd::Zero(n);
    for (const auto& [i, c] : order) {
      nodes.push_back(i);
      pinned.segment<3>(3 * i) = pin_of(c).position;
    }
    StepReport pass_report;
    bool screening_pass = false, cycled = false;
    VectorXd grad;  // after a final pass: grad g with the pinned rows kept (the contact forces)
    {
      const ContactPinScope scope(sim, nodes, pinned);
      VectorXd x0 = x;
      for (int d = 0; d < n; ++d)
        if (sim.fixed[d]) x0(d) = sim.fixed_values(d);
      StepObjective objective(sim, xhat, force);
      if (screening) {
        StepObjective::Checkpoint checkpoint;
        checkpoint.abs_tolerance = pass == 1 ? sim.options.abs_tolerance : screen_target;
        checkpoint.rel_tolerance = pass == 1 ? opt.screening_rel_tolerance : 0.0;
        checkpoint.stop = [&](const VectorXd& xs) {
          VectorXd grad;
          objective.Evaluate(xs, &grad, /*keep_fixed_rows=*/true);
          if (update_set(xs, grad, /*screening_pass=*/true, &cycled)) return true;
          screening = false;  // the set settled at the loose tolerance: refine it in this solve
          return false;
        };
        objective.SetCheckpoint(std::move(checkpoint));
      }
      // Later passes start from the previous solution; they must meet the
      // first pass's tolerance, not one relative to their smaller residual.
      const ToleranceScope tolerance(sim, pass == 1 ? -1.0 : first_target);
      // Each pass's solve is bounded by g at x_i with this pass's pins
      // (solver/energy_bounded_step.h).
      VectorXd previous = state.x;
      for (int d = 0; d < n; ++d)
        if (sim.fixed[d]) previous(d) = sim.fixed_values(d);
      x = SolveEnergyBounded(objective, x0, previous, solve, &pass_report);
      screening_pass = objective.checkpoint_stopped();
      if (!screening_pass && !nodes.empty()) objective.Evaluate(x, &grad, /*keep_fixed_rows=*/true);
    }
    if (pass == 1) {
      first_target = sim.options.abs_tolerance + sim.options.rel_tolerance * pass_report.initial_residual;
      screen_target = sim.options.abs_tolerance + opt.screening_rel_tolerance * pass_report.initial_residual;
      report->initial_residual = pass_report.initial_residual;
    }
    AppendSolve(pass_report, report);
    report->active_set_passes = pass;

    // A screening pass stopped because the set changed; a final pass applies
    // the test with the contact forces f_c = grad g at the pinned nodes.
    const bool changed = screening_pass || update_set(x, grad, /*screening_pass=*/false, &cycled);
    if (cycled) screening = false;
    if (sim.options.verbosity >= 2)
      std::fprintf(stderr, "  contact pass %d%s: %zu pinned nodes%s\n", pass, screening_pass ? " (screening)" : "",
                   nodes.size(), changed ? ", set changed" : "");
    if (!changed) {
      if (!nodes.empty()) CheckContactEnergy(sim, state, xhat, force, x, pass_report.final_residual);
      report->contact_nodes = nodes;
      report->contact_forces.resize(3, static_cast<Eigen::Index>(nodes.size()));
      for (size_t k = 0; k < nodes.size(); ++k)
        report->contact_forces.col(static_cast<Eigen::Index>(k)) = grad.segment<3>(3 * nodes[k]);
      return x;
    }
    if (pass >= opt.max_passes) {
      std::ostringstream msg;
      msg << "frictional contact: the active set did not settle in " << opt.max_passes
          << " passes (frictional_contact_options.max_passes; " << nodes.size() << " nodes pinned in the last pass)";
      throw SolverError(SolverStatus::kActiveSetNotConverged, msg.str());
    }
  }
}

void AddPinGradient(SimulatorImpl& sim, StepLinearization& lin, const State& previous, const std::vector<int>& nodes,
                    const VectorXd& b, const VectorXd& z, VectorXd* gx, VectorXd* gv) {
  if (nodes.empty()) return;
  const VectorXd hz = lin.ApplyUnmasked(z);
  std::vector<const ContactSurface*> surface_of(sim.fem.num_nodes(), nullptr);
  for (const FrictionalContact& c : sim.scene.frictional_contacts)
    for (const int i : c.nodes) surface_of[i] = &c.surface;
  for (const int i : nodes) {
    DIFFPD_CHECK(surface_of[i] != nullptr, "pinned node " << i << " is not a frictional contact candidate");
    const ContactPin pin =
        ComputeContactPin(*surface_of[i], previous.x.segment<3>(3 * i), previous.v.segment<3>(3 * i), sim.h());
    const Vec3 dl_dpin = b.segment<3>(3 * i) - hz.segment<3>(3 * i);
    gx->segment<3>(3 * i) += pin.d_dx.transpose() * dl_dpin;
    gv->segment<3>(3 * i) += pin.d_dv.transpose() * dl_dpin;
  }
}

}  // namespace diffpd::internal
