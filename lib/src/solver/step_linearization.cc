// Linear solves with the exact Hessian of one step, H = M/h^2 + hess E(x),
// used by the backward (adjoint) and forward-mode (tangent) passes.
//
// Newton methods assemble H and factorise it (CHOLMOD, or PCG for
// newton-pcg). PD methods never assemble H: they apply it element by element
// and iterate with the forward factor of A as preconditioner,
//   fixed point (DiffPD):  A z_{k+1} = b + (A - H) z_k,
//   or L-BFGS on 1/2 z^T H z - b^T z with H0 = A^{-1} and exact steps.
// Residual growth, stagnation or negative curvature triggers a reported
// fallback to a direct solve of the assembled H (CHOLMOD, then sparse LU
// when H is indefinite).
#include <cmath>
#include <cstdio>
#include <deque>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseLU>

#include "diffpd/error.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

StepLinearization::StepLinearization(SimulatorImpl& sim, const VectorXd& x, bool static_problem)
    : sim_(sim), x_(x) {
  inertia_ = static_problem ? VectorXd::Zero(sim.num_dofs()) : VectorXd(sim.Mass() / (sim.h() * sim.h()));
  const Method m = sim.options.method;
  if (m == Method::kPd || m == Method::kPdLbfgs) PackedBlocks();
}

const std::vector<double>& StepLinearization::PackedBlocks() {
  if (packed_blocks_.empty()) {
    std::vector<double> blocks;
    sim_.elastic.ElementHessians(x_, sim_.lame(), /*project_spd=*/false, &blocks, sim_.threads());
    sim_.elastic.PackElementMatrices(blocks, &packed_blocks_);
  }
  return packed_blocks_;
}

void StepLinearization::AssembleMatrix() {
  if (have_matrix_) return;
  std::vector<double> blocks;
  sim_.elastic.ElementHessians(x_, sim_.lame(), /*project_spd=*/false, &blocks, sim_.threads());
  sim_.aux.AddElementHessians(x_, sim_.activation, /*project_spd=*/false, &blocks);
  sim_.hessian_assembler().Assemble(blocks, inertia_, sim_.fixed, &matrix_);
  have_matrix_ = true;
}

VectorXd StepLinearization::Apply(const VectorXd& z) {
  VectorXd out = ApplyUnmasked(z);
  sim_.ZeroFixed(&out);
  return out;
}

VectorXd StepLinearization::ApplyUnmasked(const VectorXd& z) {
  VectorXd zf = z;
  sim_.ZeroFixed(&zf);
  VectorXd out;
  sim_.elastic.ApplyElementMatrices(PackedBlocks(), zf, &out, sim_.threads());
  sim_.aux.AddHessianProduct(x_, sim_.activation, zf, &out);
  out.array() += inertia_.array() * zf.array();
  return out;
}

bool StepLinearization::DirectSolve(const VectorXd& b, VectorXd* z) {
  if (!llt_) {
    AssembleMatrix();
    llt_ = std::make_unique<CholmodSolver>();
    factored_ = llt_->Factorize(matrix_);
  }
  VectorXd rhs = b;
  sim_.ZeroFixed(&rhs);
  if (factored_) {
    *z = llt_->Solve(rhs);
  } else {  // indefinite H (e.g. strongly compressed elements): sparse LU
    Eigen::SparseLU<SparseMatrix> lu;
    lu.compute(matrix_);
    if (lu.info() != Eigen::Success) return false;
    *z = lu.solve(rhs);
  }
  sim_.ZeroFixed(z);
  return z->allFinite();
}

bool StepLinearization::IterativeSolve(const VectorXd& b, VectorXd* z, int* iterations) {
  PdSystem& pd = sim_.pd_system();
  const SolverOptions& opt = sim_.options;
  VectorXd rhs = b;
  sim_.ZeroFixed(&rhs);
  const double bnorm = rhs.norm();
  *z = VectorXd::Zero(rhs.size());
  if (bnorm == 0) return true;
  const double tol = opt.backward_rel_tolerance * bnorm;
  VectorXd r = rhs;  // r = b - H z
  if (opt.pd_backward == PdBackwardMethod::kFixedPoint) {
    double best = bnorm;
    int stalled = 0;
    for (int it = 1; it <= opt.backward_max_iterations; ++it) {
      *z += pd.Solve(r);
      r = rhs - Apply(*z);
      const double rn = r.norm();
      *iterations = it;
      if (!std::isfinite(rn)) return false;
      if (rn <= tol) return true;
      if (rn > 10 * best) return false;  // growth: spectral radius of A^{-1} dA >= 1
      if (rn < 0.999 * best) {
        best = rn;
        stalled = 0;
      } else if (++stalled >= 20) {
        return false;  // stagnation
      }
    }
    return false;
  }
  // L-BFGS with exact steps on the quadratic; gradient of the quadratic is -r.
  std::deque<VectorXd> s_list, y_list;
  std::deque<double> rho_list;
  std::vector<double> alpha(opt.lbfgs_history);
  for (int it = 1; it <= opt.backward_max_iterations; ++it) {
    VectorXd q = -r;
    const int k = static_cast<int>(s_list.size());
    for (int j = k - 1; j >= 0; --j) {
      alpha[j] = rho_list[j] * s_list[j].dot(q);
      q -= alpha[j] * y_list[j];
    }
    VectorXd p = pd.Solve(q);
    for (int j = 0; j < k; ++j) p += (alpha[j] - rho_list[j] * y_list[j].dot(p)) * s_list[j];
    p = -p;
    sim_.ZeroFixed(&p);
    const VectorXd hp = Apply(p);
    const double curvature = p.dot(hp);
    if (!(curvature > 0)) return false;  // negative curvature: H is not positive definite
    const double step = r.dot(p) / curvature;
    *z += step * p;
    r -= step * hp;
    *iterations = it;
    const double rn = r.norm();
    if (!std::isfinite(rn)) return false;
    if (rn <= tol) {
      // Guard against drift of the recurrence: confirm with a true residual.
      const double true_rn = (rhs - Apply(*z)).norm();
      if (true_rn <= 10 * tol) return true;
      r = rhs - Apply(*z);
    }
    if (static_cast<int>(s_list.size()) == opt.lbfgs_history) {
      s_list.pop_front();
      y_list.pop_front();
      rho_list.pop_front();
    }
    s_list.push_back(step * p);
    y_list.push_back(step * hp);
    rho_list.push_back(1.0 / (step * step * curvature));
  }
  return false;
}

bool StepLinearization::PcgSolve(const VectorXd& b, VectorXd* z, int* iterations) {
  AssembleMatrix();
  VectorXd rhs = b;
  sim_.ZeroFixed(&rhs);
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
  cg.setTolerance(sim_.options.backward_rel_tolerance);
  cg.setMaxIterations(sim_.options.pcg_max_iterations);
  cg.compute(matrix_);
  if (cg.info() != Eigen::Success) return false;
  *z = cg.solve(rhs);
  *iterations = static_cast<int>(cg.iterations());
  sim_.ZeroFixed(z);
  return cg.info() == Eigen::Success && z->allFinite();
}

VectorXd StepLinearization::Solve(const VectorXd& b, BackwardReport* report) {
  VectorXd z;
  const Method m = sim_.options.method;
  int iterations = 0;
  bool ok = false;
  bool iterative = false;
  if (m == Method::kPd || m == Method::kPdLbfgs) {
    iterative = true;
    ok = IterativeSolve(b, &z, &iterations);
  } else if (m == Method::kNewtonPcg) {
    iterative = true;
    ok = PcgSolve(b, &z, &iterations);
  }
  if (report) report->linear_iterations += iterations;
  if (ok) return z;
  if (iterative) {
    if (report) ++report->fallbacks;
    if (sim_.options.verbosity >= 1)
      std::fprintf(stderr, "%s backward: iterative adjoint solve failed after %d iterations; falling back to a direct solve\n",
                   ToString(m), iterations);
  }
  if (!DirectSolve(b, &z))
    throw SolverError(SolverStatus::kFactorizationFailed,
                      std::string(ToString(m)) + " backward: the step Hessian is singular; no gradient exists here");
  return z;
}

}  // namespace diffpd::internal

namespace diffpd::internal {

// The single-column iterations above, run for all columns in lockstep so that
// each iteration makes one A^{-1} solve with several right-hand sides.
void StepLinearization::IterativeSolveColumns(const MatrixXd& b, MatrixXd* z, std::vector<char>* ok,
                                              int* iterations) {
  PdSystem& pd = sim_.pd_system();
  const SolverOptions& opt = sim_.options;
  const int cols = static_cast<int>(b.cols());
  MatrixXd rhs = b;
  for (int c = 0; c < cols; ++c) {
    VectorXd col = rhs.col(c);
    sim_.ZeroFixed(&col);
    rhs.col(c) = col;
  }
  *z = MatrixXd::Zero(rhs.rows(), cols);
  ok->assign(cols, 0);
  MatrixXd r = rhs;
  std::vector<double> tol(cols), best(cols);
  std::vector<int> stalled(cols, 0);
  std::vector<int> active;
  for (int c = 0; c < cols; ++c) {
    const double bnorm = rhs.col(c).norm();
    tol[c] = opt.backward_rel_tolerance * bnorm;
    best[c] = bnorm;
    if (bnorm == 0)
      (*ok)[c] = 1;
    else
      active.push_back(c);
  }
  // Per-column L-BFGS memory.
  std::vector<std::deque<VectorXd>> s_list(cols), y_list(cols);
  std::vector<std::deque<double>> rho_list(cols);
  std::vector<std::vector<double>> alpha(cols, std::vector<double>(opt.lbfgs_history));
  const bool fixed_point = opt.pd_backward == PdBackwardMethod::kFixedPoint;
  for (int it = 1; it <= opt.backward_max_iterations && !active.empty(); ++it) {
    const int na = static_cast<int>(active.size());
    MatrixXd q(rhs.rows(), na);
    for (int j = 0; j < na; ++j) {
      const int c = active[j];
      if (fixed_point) {
        q.col(j) = r.col(c);
        continue;
      }
      VectorXd qc = -r.col(c);
      for (int m = static_cast<int>(s_list[c].size()) - 1; m >= 0; --m) {
        alpha[c][m] = rho_list[c][m] * s_list[c][m].dot(qc);
        qc -= alpha[c][m] * y_list[c][m];
      }
      q.col(j) = qc;
    }
    const MatrixXd p_all = pd.Solve(q);
    *iterations += na;
    std::vector<int> still;
    for (int j = 0; j < na; ++j) {
      const int c = active[j];
      bool converged = false, failed = false;
      if (fixed_point) {
        z->col(c) += p_all.col(j);
        r.col(c) = rhs.col(c) - Apply(z->col(c));
        const double rn = r.col(c).norm();
        if (!std::isfinite(rn) || rn > 10 * best[c]) {
          failed = true;
        } else if (rn <= tol[c]) {
          converged = true;
        } else if (rn < 0.999 * best[c]) {
          best[c] = rn;
          stalled[c] = 0;
        } else if (++stalled[c] >= 20) {
          failed = true;
        }
      } else {
        VectorXd p = p_all.col(j);
        const int k = static_cast<int>(s_list[c].size());
        for (int m = 0; m < k; ++m) p += (alpha[c][m] - rho_list[c][m] * y_list[c][m].dot(p)) * s_list[c][m];
        p = -p;
        sim_.ZeroFixed(&p);
        const VectorXd hp = Apply(p);
        const double curvature = p.dot(hp);
        if (!(curvature > 0)) {
          failed = true;
        } else {
          const double step = r.col(c).dot(p) / curvature;
          z->col(c) += step * p;
          r.col(c) -= step * hp;
          const double rn = r.col(c).norm();
          if (!std::isfinite(rn)) {
            failed = true;
          } else {
            if (rn <= tol[c]) {
              r.col(c) = rhs.col(c) - Apply(z->col(c));  // confirm with a true residual
              if (r.col(c).norm() <= 10 * tol[c]) converged = true;
            }
            if (static_cast<int>(s_list[c].size()) == opt.lbfgs_history) {
              s_list[c].pop_front();
              y_list[c].pop_front();
              rho_list[c].pop_front();
            }
            s_list[c].push_back(step * p);
            y_list[c].push_back(step * hp);
            rho_list[c].push_back(1.0 / (step * step * curvature));
          }
        }
      }
      if (converged)
        (*ok)[c] = 1;
      else if (!failed)
        still.push_back(c);
    }
    active.swap(still);
  }
}

MatrixXd StepLinearization::SolveColumns(const MatrixXd& b, BackwardReport* report) {
  const Method m = sim_.options.method;
  const int cols = static_cast<int>(b.cols());
  MatrixXd z = MatrixXd::Zero(b.rows(), cols);
  std::vector<char> ok(cols, 0);
  int iterations = 0;
  bool iterative = false;
  if (m == Method::kPd || m == Method::kPdLbfgs) {
    iterative = true;
    IterativeSolveColumns(b, &z, &ok, &iterations);
  } else if (m == Method::kNewtonPcg) {
    iterative = true;
    for (int c = 0; c < cols; ++c) {
      VectorXd zc;
      int it = 0;
      ok[c] = PcgSolve(b.col(c), &zc, &it);
      iterations += it;
      if (ok[c]) z.col(c) = zc;
    }
  }
  if (report) report->linear_iterations += iterations;
  for (int c = 0; c < cols; ++c) {
    if (ok[c]) continue;
    if (iterative) {
      if (report) ++report->fallbacks;
      if (sim_.options.verbosity >= 1)
        std::fprintf(stderr, "%s tangent: iterative solve of column %d failed; falling back to a direct solve\n",
                     ToString(m), c);
    }
    VectorXd zc;
    if (!DirectSolve(b.col(c), &zc))
      throw SolverError(SolverStatus::kFactorizationFailed,
                        std::string(ToString(m)) + " tangent: the step Hessian is singular; no derivative exists here");
    z.col(c) = zc;
  }
  return z;
}

}  // namespace diffpd::internal
