// Linear solves with the exact Hessian of one step, H = M/h^2 + hess E(x),
// used by the backward (adjoint) and forward-mode (tangent) passes.
//
// Newton methods assemble H and factorise it (the simulator's
// HessianFactorization: CHOLMOD, or simplicial LDL^T for newton-ldlt), or
// solve it by PCG (newton-pcg). PD methods, by SolverOptions::adjoint_solver,
// either apply H element by element and iterate with the forward factor of A
// as preconditioner (preconditioned_iteration.h: CG, the DiffPD fixed point
// or L-BFGS), or factorise the assembled H like Newton, or choose between
// the two per step by their estimated costs (adjoint_cost_model.h).
// Residual growth, stagnation or negative curvature of the iteration
// triggers a reported fallback to the direct solve (sparse LU when H is
// indefinite).
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseLU>

#include "diffpd/error.h"
#include "solver/adjoint_recycling.h"
#include "solver/preconditioned_iteration.h"
#include "solver/rigid_mode_correction.h"
#include "solver/simulator_impl.h"

namespace diffpd::internal {
namespace {

bool IsPdMethod(Method m) { return m == Method::kPd || m == Method::kPdLbfgs; }

}  // namespace

StepLinearization::StepLinearization(SimulatorImpl& sim, const VectorXd& x, bool static_problem)
    : sim_(sim), x_(x), static_(static_problem), rel_tolerance_(sim.options.backward_rel_tolerance) {
  inertia_ = static_problem ? VectorXd::Zero(sim.num_dofs()) : VectorXd(sim.Mass() / (sim.h() * sim.h()));
  packed_blocks_.swap(sim.packed_hessian_storage);  // empty if another linearization holds it
}

StepLinearization::~StepLinearization() {
  if (sim_.packed_hessian_storage.capacity() < packed_blocks_.capacity())
    sim_.packed_hessian_storage.swap(packed_blocks_);
}

const std::vector<double>& StepLinearization::PackedBlocks() {
  if (have_blocks_) return packed_blocks_;
  sim_.elastic.PackedElementHessians(x_, sim_.lame(), &packed_blocks_, sim_.threads(),
                                     keep_lame_gradients_ ? &lame_gradients_ : nullptr);
  if (!sim_.aux.empty()) {
    // The auxiliary energies' element Hessians (muscles, penalty contact)
    // join the packed elastic ones: one packed product per application of
    // H instead of recomputing every muscle sample's Hessian each time (on
    // the paper's tendon, a muscle in every element, that product took 3-10x
    // the packed one).
    const size_t block = 9 * static_cast<size_t>(sim_.fem.nodes_per_element()) * sim_.fem.nodes_per_element();
    std::vector<double> aux(block * sim_.fem.num_elements(), 0.0), packed_aux;
    sim_.aux.AddElementHessians(x_, sim_.activation, /*project_spd=*/false, &aux);
    sim_.elastic.PackElementMatrices(aux, &packed_aux);
    Eigen::Map<VectorXd>(packed_blocks_.data(), packed_blocks_.size()) +=
        Eigen::Map<const VectorXd>(packed_aux.data(), packed_aux.size());
  }
  have_blocks_ = true;
  return packed_blocks_;
}

void StepLinearization::AssembleMatrix() {
  if (have_matrix_) return;
  sim_.hessian_assembler().AssemblePacked(PackedBlocks(), {}, inertia_, sim_.fixed, &matrix_);
  have_matrix_ = true;
}

VectorXd StepLinearization::Apply(const VectorXd& z) {
  VectorXd out = ApplyUnmasked(z);
  sim_.ZeroFixed(&out);
  return out;
}

MatrixXd StepLinearization::ApplyColumns(const MatrixXd& z) {
  MatrixXd zf = z;
  for (int d = 0; d < zf.rows(); ++d)
    if (sim_.fixed[d]) zf.row(d).setZero();
  MatrixXd out;
  sim_.elastic.ApplyElementMatricesToColumns(PackedBlocks(), zf, &out, sim_.threads());  // elastic and auxiliary
  for (Eigen::Index c = 0; c < out.cols(); ++c) out.col(c).array() += inertia_.array() * zf.col(c).array();
  for (int d = 0; d < out.rows(); ++d)
    if (sim_.fixed[d]) out.row(d).setZero();
  return out;
}

void StepLinearization::PartLameDots(const VectorXd& z, VectorXd* dmu, VectorXd* dlambda) {
  if (lame_gradients_.empty()) {
    sim_.elastic.PartLameDots(x_, z, sim_.part_of_element, sim_.num_parts(), dmu, dlambda, sim_.threads());
    return;
  }
  sim_.elastic.LameDotsFromUnitGradients(lame_gradients_, z, sim_.part_of_element, sim_.num_parts(), dmu, dlambda);
}

VectorXd StepLinearization::ApplyUnmasked(const VectorXd& z) {
  ++hessian_products_;
  VectorXd zf = z;
  sim_.ZeroFixed(&zf);
  VectorXd out;
  sim_.elastic.ApplyElementMatrices(PackedBlocks(), zf, &out, sim_.threads());  // elastic and auxiliary
  out.array() += inertia_.array() * zf.array();
  return out;
}

bool StepLinearization::DirectSolve(const MatrixXd& b, MatrixXd* z) {
  HessianFactorization& factor = sim_.hessian_factorization();
  if (!(factored_ && factor_id_ == factor.num_factorizations()) && !lu_) {
    // Not factorised yet, or another solve has factorised since.
    AssembleMatrix();
    factored_ = factor.Factorize(matrix_);
    factor_id_ = factor.num_factorizations();
    if (!factored_) {  // indefinite H (e.g. strongly compressed elements): sparse LU
      lu_ = std::make_unique<Eigen::SparseLU<SparseMatrix>>();
      lu_->compute(matrix_);
      if (lu_->info() != Eigen::Success) return false;
    }
  }
  MatrixXd rhs = b;
  for (int d = 0; d < rhs.rows(); ++d)
    if (sim_.fixed[d]) rhs.row(d).setZero();
  if (lu_) {
    *z = lu_->solve(rhs);
  } else {
    *z = factor.Solve(rhs);
  }
  for (int d = 0; d < z->rows(); ++d)
    if (sim_.fixed[d]) z->row(d).setZero();
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
  iteration.rel_tolerance = rel_tolerance_;
  iteration.max_iterations = opt.backward_max_iterations;
  iteration.lbfgs_history = opt.lbfgs_history;
  // A^-1, plus the rigid modes' correction (rigid_mode_correction.h) for the
  // Krylov methods; the fixed point keeps DiffPD's A^-1.
  std::optional<RigidModeCorrection> rigid;
  if (sim_.UseRigidModeCorrection(static_) && opt.pd_backward != PdBackwardMethod::kFixedPoint) {
    rigid.emplace(x_, sim_.fixed);
    rigid->SetHessianProducts(ApplyColumns(rigid->modes()));
  }
  const std::function<VectorXd(const VectorXd&)> apply_h = [this](const VectorXd& v) { return Apply(v); };
  const std::function<MatrixXd(const MatrixXd&)> apply_h_columns = [this](const MatrixXd& v) {
    return ApplyColumns(v);
  };
  // From the Galerkin guess on the previous steps' solutions when there are
  // any: the iteration solves for the correction, to the tolerance relative
  // to the right-hand side itself.
  MatrixXd guess, residual;
  const bool guessed = recycling_ && recycling_->size() > 0;
  if (guessed) {
    recycling_->Guess(rhs, apply_h_columns, &guess, &residual);
    // Earlier steps may have other fixed DoFs (contact pins): H W was formed
    // with them zeroed (Apply), so zeroing them in the guess keeps r0 exact.
    for (int d = 0; d < guess.rows(); ++d)
      if (sim_.fixed[d]) guess.row(d).setZero();
    iteration.reference_norms = rhs.colwise().norm().transpose();
  }
  SolvePreconditioned(
      iteration, guessed ? residual : rhs, apply_h,
      [this, &pd, &rigid](const MatrixXd& r) {
        pd_solves_ += static_cast<int>(r.cols());
        MatrixXd out = pd.Solve(r);
        if (rigid) rigid->Add(r, &out);
        return out;
      },
      z, ok, iterations);
  if (guessed)
    for (int c = 0; c < z->cols(); ++c)
      if ((*ok)[c]) z->col(c) += guess.col(c);
}

bool StepLinearization::PcgSolve(const VectorXd& b, VectorXd* z, int* iterations) {
  AssembleMatrix();
  VectorXd rhs = b;
  sim_.ZeroFixed(&rhs);
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, Eigen::IncompleteCholesky<double>> cg;
  cg.setTolerance(rel_tolerance_);
  cg.setMaxIterations(sim_.options.pcg_max_iterations);
  cg.compute(matrix_);
  if (cg.info() != Eigen::Success) return false;
  *z = cg.solve(rhs);
  *iterations = static_cast<int>(cg.iterations());
  sim_.ZeroFixed(z);
  return cg.info() == Eigen::Success && z->allFinite();
}

double StepLinearization::DirectAdjointBytes() {
  return kHessianFactorEntriesPerPdEntry * sizeof(double) * sim_.pd_system().factor_nonzeros();
}

bool StepLinearization::DirectAdjointFits() {
  return sim_.options.adjoint_solver == AdjointSolver::kDirect ||
         DirectAdjointBytes() <= sim_.options.adjoint_direct_max_bytes;
}

AdjointWorkSizes StepLinearization::WorkSizes() {
  AdjointWorkSizes sizes;
  sizes.dofs = static_cast<double>(sim_.num_dofs());
  sizes.packed_entries = static_cast<double>(PackedBlocks().size());
  const PdSystem& pd = sim_.pd_system();
  sizes.pd_solve_entries = pd.SolveEntries();
  const HessianFactorization& factor = sim_.hessian_factorization();
  sizes.hessian_analysed = factor.factor_nonzeros() > 0;
  if (sizes.hessian_analysed) {
    sizes.hessian_factor_entries = factor.factor_nonzeros();
    sizes.hessian_factor_flops = factor.factor_flops();
  } else {
    // H is A's pattern with 3 x 3 blocks: 9 times the entries, 27 times the flops.
    sizes.hessian_factor_entries = kHessianFactorEntriesPerPdEntry * pd.factor_nonzeros();
    sizes.hessian_factor_flops = 27 * pd.factor_flops();
  }
  return sizes;
}

VectorXd StepLinearization::Solve(const VectorXd& b, BackwardReport* report) {
  return SolveSystem(b, &sim_.backward_cost_model(), /*tangent=*/false, report).col(0);
}

MatrixXd StepLinearization::SolveColumns(const MatrixXd& b, BackwardReport* report) {
  return SolveSystem(b, &sim_.tangent_cost_model(static_cast<int>(b.cols())), /*tangent=*/true, report);
}

MatrixXd StepLinearization::SolveSystem(const MatrixXd& b, AdjointCostModel* model, bool tangent,
                                        BackwardReport* report) {
  const Method m = sim_.options.method;
  const char* pass = tangent ? "tangent" : "backward";
  if (!b.allFinite())
    throw SolverError(SolverStatus::kNonFinite,
                      tangent ? "the right-hand sides B are not finite" : "the right-hand side b is not finite");
  const int cols = static_cast<int>(b.cols());
  MatrixXd z = MatrixXd::Zero(b.rows(), cols);
  std::vector<char> ok(cols, 0);
  int iterations = 0;
  // The route: Newton methods their own solver, PD methods by adjoint_solver.
  bool iterative = m == Method::kNewtonPcg;
  bool chosen = false;  // by the cost model
  if (IsPdMethod(m)) {
    switch (sim_.options.adjoint_solver) {
      case AdjointSolver::kIterative:
        iterative = true;
        break;
      case AdjointSolver::kDirect:
        iterative = false;
        break;
      case AdjointSolver::kAuto:
        if (DirectAdjointFits()) {
          const AdjointWorkSizes sizes = WorkSizes();
          model->SetDirectEstimate(DirectSeconds(sizes, cols) +
                                   (sizes.hessian_analysed ? 0.0 : AnalysisSeconds(sizes) / steps_left_));
          iterative = model->Next() == AdjointCostModel::Solver::kIterative;
          chosen = true;
        } else {
          iterative = true;
        }
        break;
    }
  }
  const int products_before = hessian_products_, pd_solves_before = pd_solves_;
  if (iterative && IsPdMethod(m)) {
    IterativeSolveColumns(b, &z, &ok, &iterations);
  } else if (iterative) {
    for (int c = 0; c < cols; ++c) {
      VectorXd zc;
      int it = 0;
      ok[c] = PcgSolve(b.col(c), &zc, &it);
      iterations += it;
      if (ok[c]) z.col(c) = zc;
    }
  }
  if (report) report->linear_iterations += iterations;
  std::vector<int> rest;  // columns left to the direct solve
  for (int c = 0; c < cols; ++c)
    if (!ok[c]) rest.push_back(c);
  if (!rest.empty()) {
    if (iterative && IsPdMethod(m) && !DirectAdjointFits()) {
      std::ostringstream msg;
      msg << ToString(m) << " " << pass << ": the iterative solve did not converge in "
          << sim_.options.backward_max_iterations
          << " iterations, and no direct solve falls back: its factor of the step "
          << "Hessian (about " << DirectAdjointBytes() / 1073741824.0
          << " GiB) exceeds SolverOptions::adjoint_direct_max_bytes ("
          << sim_.options.adjoint_direct_max_bytes / 1073741824.0 << " GiB)";
      throw SolverError(SolverStatus::kMaxIterations, msg.str());
    }
    if (iterative) {
      if (report) report->fallbacks += static_cast<int>(rest.size());
      if (sim_.options.verbosity >= 1) {
        if (tangent) {
          for (const int c : rest)
            std::fprintf(stderr, "%s tangent: iterative solve of column %d failed; falling back to a direct solve\n",
                         ToString(m), c);
        } else {
          std::fprintf(
              stderr,
              "%s backward: iterative adjoint solve failed after %d iterations; falling back to a direct solve\n",
              ToString(m), iterations);
        }
      }
    }
    MatrixXd rhs(b.rows(), static_cast<Eigen::Index>(rest.size()));
    for (size_t j = 0; j < rest.size(); ++j) rhs.col(j) = b.col(rest[j]);
    MatrixXd solved;
    const bool indefinite_before = lu_ != nullptr;  // DirectSolve makes lu_ once, for an indefinite H
    if (!DirectSolve(rhs, &solved))
      throw SolverError(SolverStatus::kFactorizationFailed, std::string(ToString(m)) + " " + pass +
                                                                ": the step Hessian is singular; no " +
                                                                (tangent ? "derivative" : "gradient") + " exists here");
    for (size_t j = 0; j < rest.size(); ++j) z.col(rest[j]) = solved.col(j);
    if (report && lu_ && !indefinite_before) ++report->indefinite_steps;
  }
  if (report) ++(iterative ? report->iterative_steps : report->direct_steps);
  if (recycling_) recycling_->Push(z);
  if (chosen) {
    if (iterative) {
      IterativeWork work;
      work.hessian_products = hessian_products_ - products_before;
      work.pd_solves = pd_solves_ - pd_solves_before;
      work.iterations = iterations;
      double seconds = IterativeSeconds(WorkSizes(), work);
      // A fallback's factorisation was part of this step's cost.
      if (!rest.empty()) seconds += DirectSeconds(WorkSizes(), static_cast<int>(rest.size()));
      model->Record(AdjointCostModel::Solver::kIterative, seconds);
    } else {
      model->Record(AdjointCostModel::Solver::kDirect, 0.0);
    }
  }
  return z;
}

}  // namespace diffpd::internal
