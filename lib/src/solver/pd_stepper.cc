// Projective dynamics on one implicit step (local-global) and its
// quasi-Newton variant (L-BFGS with A as the initial Hessian, Liu et al. 2017).
//
// The local-global iteration x_{k+1} = A^{-1} (M y / h^2 + sum w G^T p(x_k))
// is written in residual form, x_{k+1} = x_k - A^{-1} grad g(x_k), which is
// algebraically identical (grad g(x) = A x - M y/h^2 - sum w G^T p(x)) and
// gives the convergence test's residual for free.
#include <cstdio>
#include <optional>
#include <string>

#include "diffpd/error.h"
#include "solver/line_search.h"
#include "solver/rigid_mode_correction.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

VectorXd PdSolve(StepObjective& objective, const VectorXd& x0, StepReport* report) {
  SimulatorImpl& sim = objective.sim();
  if (!sim.elastic.all_projective())
    throw InvalidInputError(
        "method pd needs projective energies only (pd-corotated, pd-volume); use pd-lbfgs or newton");
  PdSystem& pd = sim.pd_system();
  VectorXd x = x0;
  VectorXd grad;
  objective.Evaluate(x, &grad);
  report->initial_residual = objective.ReferenceResidual(grad.norm());
  for (int it = 0;; ++it) {
    if (IterationConverged(objective, it, x, grad.norm(), report)) return x;
    x -= pd.Solve(grad);
    objective.Evaluate(x, &grad);
  }
}

namespace {

// PD-LBFGS's line search stalled at x above g's rounding floor band (both
// the quasi-Newton and the plain PD direction), or it reached max_iterations:
// Newton from x, with the same convergence test
// (SolverOptions::pd_lbfgs_newton_fallback), or the stall's error.
VectorXd NewtonFallback(StepObjective& objective, const VectorXd& x, const SolverError& stall, StepReport* report) {
  if (!objective.sim().options.pd_lbfgs_newton_fallback) throw stall;
  objective.SetReferenceResidual(report->initial_residual);
  StepReport newton;
  VectorXd out;
  try {
    out = NewtonSolve(objective, x, &newton);
  } catch (const SolverError& e) {
    throw SolverError(e.status(),
                      std::string("Newton fallback of ") + e.what() + "; Newton took over after: " + stall.what());
  }
  AppendSolve(newton, report);
  report->newton_fallback = true;
  return out;
}

}  // namespace

VectorXd PdLbfgsSolve(StepObjective& objective, const VectorXd& x0, StepReport* report) {
  SimulatorImpl& sim = objective.sim();
  PdSystem& pd = sim.pd_system();
  LbfgsPairs& pairs = sim.empty_lbfgs_pairs();
  VectorXd x = x0;
  VectorXd grad;
  double value = objective.Evaluate(x, &grad);
  report->initial_residual = objective.ReferenceResidual(grad.norm());
  std::vector<double> alpha;
  // H0 = A^-1, plus the rigid modes' correction (rigid_mode_correction.h)
  // with H's Galerkin matrix at the start.
  std::optional<RigidModeCorrection> rigid;
  if (sim.UseRigidModeCorrection(objective.is_static())) {
    rigid.emplace(x, sim.fixed);
    rigid->SetHessianProducts(
        RigidModeHessianProducts(sim, *rigid, x, objective.ElasticGradient(x, grad), objective.inertia_diagonal()));
  }
  const auto initial_inverse = [&](const VectorXd& q) {
    VectorXd r = pd.Solve(q);
    if (rigid) rigid->Add(q, &r);
    return r;
  };
  for (int it = 0;; ++it) {
    try {
      if (IterationConverged(objective, it, x, grad.norm(), report)) return x;
    } catch (const SolverError& e) {
      if (e.status() != SolverStatus::kMaxIterations) throw;
      return NewtonFallback(objective, x, e, report);  // max_iterations reached
    }
    // Two-loop recursion.
    VectorXd q = grad;
    pairs.FirstLoop(&q, &alpha);
    VectorXd r = initial_inverse(q);
    pairs.SecondLoop(alpha, &r);
    VectorXd d = -r;
    sim.ZeroFixed(&d);
    if (!(grad.dot(d) < 0)) {  // lost descent: restart from H0's direction
      pairs.Clear();
      d = -initial_inverse(grad);
      sim.ZeroFixed(&d);
    }
    const VectorXd x_old = x, grad_old = grad;
    LineSearchResult search;
    std::optional<SolverError> stall;
    const auto line_search = [&](const VectorXd& direction) {
      try {
        search = BacktrackingLineSearch(objective, direction, &x, &value, &grad);
        stall.reset();
      } catch (const SolverError& e) {
        if (e.status() != SolverStatus::kLineSearchFailed) throw;
        stall = e;
      }
    };
    line_search(d);
    if (stall && pairs.size() > 0) {
      // Stale curvature pairs can spoil the direction near convergence:
      // restart once from H0's direction.
      pairs.Clear();
      d = -initial_inverse(grad);
      sim.ZeroFixed(&d);
      line_search(d);
    }
    if (stall) return NewtonFallback(objective, x, *stall, report);
    report->line_search_steps += search.halvings;
    if (search.at_rounding_floor) return EndAtRoundingFloor(x, grad.norm(), report);
    const VectorXd s = x - x_old, y = grad - grad_old;
    const double sy = s.dot(y);
    if (sy > 1e-12 * s.norm() * y.norm()) pairs.Push(s, y, 1.0 / sy);
  }
}

}  // namespace diffpd::internal
