// Linear solves with the exact Hessian of one step, H = M/h^2 + hess E(x),
// used by the backward (adjoint) and forward-mode (tangent) passes.
//
// Newton methods assemble H and factorise it (CHOLMOD, or PCG for
// newton-pcg). PD methods never assemble H: they apply it element by element
// and iterate with the forward factor of A as preconditioner
// (preconditioned_iteration.h: CG, the DiffPD fixed point or L-BFGS).
// Residual growth, stagnation or negative curvature triggers a reported
// fallback to a direct solve of the assembled H (CHOLMOD, then sparse LU
// when H is indefinite).
#include <cstdio>
#include <optional>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseLU>

#include "diffpd/error.h"
#include "solver/preconditioned_iteration.h"
#include "solver/rigid_mode_correction.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {

StepLinearization::StepLinearization(SimulatorImpl& sim, const VectorXd& x, bool static_problem)
    : sim_(sim), x_(x), static_(static_problem) {
  inertia_ = static_problem ? VectorXd::Zero(sim.num_dofs()) : VectorXd(sim.Mass() / (sim.h() * sim.h()));
  const Method m = sim.options.method;
  if (m == Method::kPd || m == Method::kPdLbfgs) PackedBlocks();
}

const std::vector<double>& StepLinearization::PackedBlocks() {
  if (packed_blocks_.empty()) sim_.elastic.PackedElementHessians(x_, sim_.lame(), &packed_blocks_, sim_.threads());
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
  // A finite b whose solution overflows: the derivative exceeds double
  // precision, not a singular H.
  if (!z->allFinite()) throw SolverError(SolverStatus::kNonFinite, "the solution of H z = b overflowed");
  return true;
}

void StepLinearization::IterativeSolveColumns(const MatrixXd& b, MatrixXd* z, std::vector<char>* ok, int* iterations) {
  PdSystem& pd = sim_.pd_system();
  const SolverOptions& opt = sim_.options;
  MatrixXd rhs = b;
  for (int d = 0; d < rhs.rows(); ++d)
    if (sim_.fixed[d]) rhs.row(d).setZero();
  PreconditionedSolveOptions iteration;
  iteration.method = opt.pd_backward;
  iteration.rel_tolerance = opt.backward_rel_tolerance;
  iteration.max_iterations = opt.backward_max_iterations;
  iteration.lbfgs_history = opt.lbfgs_history;
  // A^-1, plus the rigid modes' correction (rigid_mode_correction.h) for the
  // Krylov methods; the fixed point keeps DiffPD's A^-1.
  std::optional<RigidModeCorrection> rigid;
  if (sim_.UseRigidModeCorrection(static_) && opt.pd_backward != PdBackwardMethod::kFixedPoint) {
    rigid.emplace(x_, sim_.fixed);
    MatrixXd hz(rhs.rows(), RigidModeCorrection::kModes);
    for (int k = 0; k < RigidModeCorrection::kModes; ++k) hz.col(k) = Apply(rigid->modes().col(k));
    rigid->SetHessianProducts(hz);
  }
  SolvePreconditioned(
      iteration, rhs, [this](const VectorXd& v) { return Apply(v); },
      [&pd, &rigid](const MatrixXd& r) {
        MatrixXd out = pd.Solve(r);
        if (rigid) rigid->Add(r, &out);
        return out;
      },
      z, ok, iterations);
}

bool StepLinearization::IterativeSolve(const VectorXd& b, VectorXd* z, int* iterations) {
  MatrixXd zs;
  std::vector<char> ok;
  IterativeSolveColumns(b, &zs, &ok, iterations);
  *z = zs.col(0);
  return ok[0] != 0;
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
  if (!b.allFinite()) throw SolverError(SolverStatus::kNonFinite, "the right-hand side b is not finite");
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
      std::fprintf(stderr,
                   "%s backward: iterative adjoint solve failed after %d iterations; falling back to a direct solve\n",
                   ToString(m), iterations);
  }
  if (!DirectSolve(b, &z))
    throw SolverError(SolverStatus::kFactorizationFailed,
                      std::string(ToString(m)) + " backward: the step Hessian is singular; no gradient exists here");
  return z;
}

MatrixXd StepLinearization::SolveColumns(const MatrixXd& b, BackwardReport* report) {
  const Method m = sim_.options.method;
  if (!b.allFinite()) throw SolverError(SolverStatus::kNonFinite, "the right-hand sides B are not finite");
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
