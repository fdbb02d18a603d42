// Newton's method on one implicit step: projected (SPD) element Hessians,
// linear solve by CHOLMOD (pattern analysed once), by the paper-style
// simplicial LDL^T (newton-ldlt) or by PCG, Armijo line search.
#include <cstdio>
#include <string>

#include <Eigen/IterativeLinearSolvers>

#include "diffpd/error.h"
#include "solver/line_search.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {
namespace {

VectorXd SolveNewtonSystem(SimulatorImpl& sim, const SparseMatrix& h, const VectorXd& rhs) {
  if (sim.options.method == Method::kNewtonPcg) {
    VectorXd dx;
    bool ok = false;
    if (sim.options.pcg_preconditioner == PcgPreconditioner::kJacobi) {
      Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper> cg;
      cg.setTolerance(sim.options.pcg_rel_tolerance);
      cg.setMaxIterations(sim.options.pcg_max_iterations);
      cg.compute(h);
      dx = cg.solve(rhs);
      ok = cg.info() == Eigen::Success;
    } else {
      Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
      cg.setTolerance(sim.options.pcg_rel_tolerance);
      cg.setMaxIterations(sim.options.pcg_max_iterations);
      cg.compute(h);
      dx = cg.solve(rhs);
      ok = cg.info() == Eigen::Success;
    }
    if (!ok)
      throw SolverError(SolverStatus::kDiverged,
                        "newton-pcg: the conjugate-gradient solve did not reach its tolerance");
    return dx;
  }
  HessianFactorization& factor = sim.hessian_factorization();
  if (!factor.Factorize(h))
    throw SolverError(SolverStatus::kFactorizationFailed,
                      std::string(ToString(sim.options.method)) +
                          ": the projected Hessian is not positive definite (a free rigid mode?)");
  return factor.Solve(rhs);
}

}  // namespace

VectorXd NewtonSolve(StepObjective& objective, const VectorXd& x0, StepReport* report) {
  SimulatorImpl& sim = objective.sim();
  VectorXd x = x0;
  VectorXd grad;
  double value = objective.Evaluate(x, &grad);
  report->initial_residual = objective.ReferenceResidual(grad.norm());
  std::vector<double> blocks;
  SparseMatrix h;
  for (int it = 0;; ++it) {
    if (IterationConverged(objective, it, x, grad.norm(), report)) return x;
    sim.elastic.ElementHessians(x, sim.lame(), /*project_spd=*/true, &blocks, sim.threads());
    sim.aux.AddElementHessians(x, sim.activation, /*project_spd=*/true, &blocks);
    sim.hessian_assembler().Assemble(blocks, objective.inertia_diagonal(), sim.fixed, &h);
    VectorXd rhs = -grad;
    VectorXd dx = SolveNewtonSystem(sim, h, rhs);
    sim.ZeroFixed(&dx);
    CheckFinite(dx, "the Newton step");
    const LineSearchResult search = BacktrackingLineSearch(objective, dx, &x, &value, &grad);
    report->line_search_steps += search.halvings;
    if (search.at_rounding_floor) return EndAtRoundingFloor(x, grad.norm(), report);
  }
}

}  // namespace diffpd::internal
