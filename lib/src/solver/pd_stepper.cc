// Projective dynamics on one implicit step (local-global) and its
// quasi-Newton variant (L-BFGS with A as the initial Hessian, Liu et al. 2017).
//
// The local-global iteration x_{k+1} = A^{-1} (M y / h^2 + sum w G^T p(x_k))
// is written in residual form, x_{k+1} = x_k - A^{-1} grad g(x_k), which is
// algebraically identical (grad g(x) = A x - M y/h^2 - sum w G^T p(x)) and
// gives the convergence test's residual for free.
#include <cstdio>
#include <deque>

#include "diffpd/error.h"
#include "solver/line_search.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

VectorXd PdSolve(StepObjective& objective, const VectorXd& x0, StepReport* report) {
  SimulatorImpl& sim = objective.sim();
  if (!sim.elastic.all_projective())
    throw InvalidInputError("method pd needs projective energies only (pd-corotated, pd-volume); use pd-lbfgs or newton");
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

VectorXd PdLbfgsSolve(StepObjective& objective, const VectorXd& x0, StepReport* report) {
  SimulatorImpl& sim = objective.sim();
  PdSystem& pd = sim.pd_system();
  const int m = sim.options.lbfgs_history;
  std::deque<VectorXd> s_list, y_list;
  std::deque<double> rho_list;
  VectorXd x = x0;
  VectorXd grad;
  double value = objective.Evaluate(x, &grad);
  report->initial_residual = objective.ReferenceResidual(grad.norm());
  std::vector<double> alpha(m);
  for (int it = 0;; ++it) {
    if (IterationConverged(objective, it, x, grad.norm(), report)) return x;
    // Two-loop recursion with H0 = A^{-1}.
    VectorXd q = grad;
    const int k = static_cast<int>(s_list.size());
    for (int j = k - 1; j >= 0; --j) {
      alpha[j] = rho_list[j] * s_list[j].dot(q);
      q -= alpha[j] * y_list[j];
    }
    VectorXd r = pd.Solve(q);
    for (int j = 0; j < k; ++j) {
      const double beta = rho_list[j] * y_list[j].dot(r);
      r += (alpha[j] - beta) * s_list[j];
    }
    VectorXd d = -r;
    sim.ZeroFixed(&d);
    if (!(grad.dot(d) < 0)) {  // lost descent: restart from the PD direction
      s_list.clear();
      y_list.clear();
      rho_list.clear();
      d = -pd.Solve(grad);
    }
    const VectorXd x_old = x, grad_old = grad;
    try {
      report->line_search_steps += BacktrackingLineSearch(objective, d, &x, &value, &grad);
    } catch (const SolverError& e) {
      // Stale curvature pairs can spoil the direction near convergence:
      // restart once from the plain PD direction before giving up.
      if (e.status() != SolverStatus::kLineSearchFailed || s_list.empty()) throw;
      s_list.clear();
      y_list.clear();
      rho_list.clear();
      d = -pd.Solve(grad);
      sim.ZeroFixed(&d);
      report->line_search_steps += BacktrackingLineSearch(objective, d, &x, &value, &grad);
    }
    VectorXd s = x - x_old, y = grad - grad_old;
    const double sy = s.dot(y);
    if (sy > 1e-12 * s.norm() * y.norm()) {
      if (static_cast<int>(s_list.size()) == m) {
        s_list.pop_front();
        y_list.pop_front();
        rho_list.pop_front();
      }
      s_list.push_back(std::move(s));
      y_list.push_back(std::move(y));
      rho_list.push_back(1.0 / sy);
    }
  }
}

}  // namespace diffpd::internal
