// State shared by the simulator's steppers and adjoints (internal).
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/SparseLU>

#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/solver_options.h"
#include "fem/auxiliary_energies.h"
#include "fem/elastic_forces.h"
#include "fem/fem_model.h"
#include "fem/lame_field.h"
#include "fem/mass_model.h"
#include "forces/state_forces.h"
#include "solver/adjoint_cost_model.h"
#include "solver/adjoint_work.h"
#include "solver/adjoint_recycling.h"
#include "solver/hessian_assembler.h"
#include "solver/hessian_factorization.h"
#include "solver/lbfgs_pairs.h"
#include "solver/pd_system.h"

namespace diffpd::internal {

class SimulatorImpl {
 public:
  SimulatorImpl(const Scene& scene, const SolverOptions& options);

  Scene scene;
  SolverOptions options;
  FemModel fem;
  // Material parts (scene/material_regions.h): part 0 the base material,
  // part r + 1 material region r. Empty without regions (one part).
  std::vector<int> part_of_element;
  MassModel mass_model;  // M from every part's density
  ElasticForces elastic;
  AuxiliaryEnergies aux;     // muscles, penalty contact (empty: no cost)
  StateForces state_forces;  // damping, hydrodynamics, penalty friction
  // Muscle activation of the step being solved or differentiated (empty:
  // rest). Step, Backward and SolveQuasiStatic set it (ActivationScope in
  // forces/activation_scope.h); anything else building a StepObjective or
  // StepLinearization for a step must set it too.
  VectorXd activation;
  // 3n flags. During a step with frictional contact the active nodes are
  // added (and their pins to fixed_values) by ContactPinScope
  // (contact/contact_pin_scope.h), and removed after.
  std::vector<char> fixed;
  VectorXd fixed_values;  // 3n, Dirichlet positions (zero at free DoFs)
  // The diagonal of the rest mesh's bounding box (m), the scale of
  // SolverOptions::max_extent_ratio.
  double rest_extent = 0;

  double h() const { return options.time_step; }
  int threads() const { return options.num_threads; }
  int num_dofs() const { return fem.mesh().num_dofs(); }

  // Material parts: 1 + number of material regions.
  int num_parts() const { return 1 + static_cast<int>(scene.material_regions.size()); }
  const MaterialParameters& part_material(int part) const {
    return part == 0 ? scene.material : scene.material_regions[part - 1].material;
  }
  // Replace the base material / region r's material (both validated by the
  // caller) and update the Lame field and the mass; the PD factor follows
  // lazily.
  void SetMaterial(const MaterialParameters& material);
  void SetRegionMaterial(int region, const MaterialParameters& material);
  // The Lame parameters of every element: uniform scalars when every part
  // has the same (mu, lambda) (always without regions), else per element.
  // Valid until the next material change.
  LameField lame() const;

  // Mass per DoF (3n, kg).
  const VectorXd& Mass() const { return mass_model.mass(); }
  // Explicit force of a step: gravity (if declared) plus the input's force.
  VectorXd ExplicitForce(const StepInput& input) const;
  // Sets fixed DoFs of v to zero.
  void ZeroFixed(VectorXd* v) const;

  // Lazily built solvers.
  HessianAssembler& hessian_assembler();
  PdSystem& pd_system();  // factor made current for (h, rho, PD weight)
  // PD-LBFGS's pairs, emptied, for options.lbfgs_history pairs of 3n-vectors
  // (kept between steps: no allocation per step).
  LbfgsPairs& empty_lbfgs_pairs();
  // Whether PD's preconditioners add the rigid modes' correction
  // (rigid_mode_correction.h): the option is on, the body has no Dirichlet
  // DoFs of its own (frictional contact's pins do not count) and the solve
  // is dynamic.
  bool UseRigidModeCorrection(bool static_problem) const {
    return options.rigid_mode_correction && scene.dirichlet.dofs.empty() && !static_problem;
  }
  // The direct solver of assembled step Hessians for the current method:
  // Newton's iterations, PD-LBFGS's Newton fallback and every direct
  // adjoint or tangent solve (simplicial LDL^T for newton-ldlt, else
  // CHOLMOD's supernodal Cholesky, its analysis kept across steps).
  HessianFactorization& hessian_factorization();
  // The cost estimates behind AdjointSolver::kAuto: one model for the
  // backward pass (one right-hand side per step) and one per number of
  // tangent directions. Reset by ResetAdjointCostModels (SetOptions).
  AdjointCostModel& backward_cost_model() { return backward_cost_; }
  AdjointCostModel& tangent_cost_model(int directions) { return tangent_cost_[directions]; }
  void ResetAdjointCostModels();
  // The storage of the step Hessian's packed element matrices, lent to one
  // StepLinearization at a time (kept between steps: a backward pass
  // allocates and clears it once, not once per step).
  std::vector<double> packed_hessian_storage;
  int pd_factorizations() const { return pd_ ? pd_->num_factorizations() : 0; }
  double pd_factorization_seconds() const { return pd_ ? pd_->factorization_seconds() : 0.0; }
  std::size_t pd_factor_copy_bytes() const { return pd_ ? pd_->copy_bytes() : 0; }

 private:
  void MaterialsChanged();

  bool uniform_lame_ = true;
  std::vector<double> element_mu_, element_lambda_;  // per element when !uniform_lame_
  std::unique_ptr<HessianAssembler> hessian_;
  std::unique_ptr<PdSystem> pd_;
  std::unique_ptr<LbfgsPairs> lbfgs_pairs_;
  std::unique_ptr<HessianFactorization> hessian_factorization_;
  AdjointCostModel backward_cost_;
  std::map<int, AdjointCostModel> tangent_cost_;
};

// "" when a rollout's recorded materials (base and regions), time step and
// method are the simulator's current ones (the condition of Backward and
// Tangents); else what differs, completing "the rollout was made with ...":
// "another time step (0.01 s) than the simulator's current one (0.02 s)".
std::string SettingsMismatch(const SimulatorImpl& sim, const MaterialParameters& material,
                             const std::vector<MaterialParameters>& region_materials, const SolverOptions& options);
// Gravity's acceleration at every DoF (3n, m/s^2; zero without gravity).
VectorXd GravityPerDof(const SimulatorImpl& sim);

// The objective of one implicit Euler step over the free DoFs:
//   g(x) = 1/(2 h^2) (x - xhat)^T M (x - xhat) - f^T x + E(x),
//   grad g(x) = M (x - xhat) / h^2 - f + grad E(x),
// with xhat = x_i + h v_i and f the explicit force. With `static_problem`
// the inertia term is dropped (equilibrium solve).
class StepObjective {
 public:
  StepObjective(SimulatorImpl& sim, VectorXd xhat, VectorXd force, bool static_problem = false);
  // g(x); if grad != nullptr also grad g, zero at fixed DoFs unless
  // keep_fixed_rows (then the fixed rows hold the reaction, as in g with
  // those DoFs free).
  double Evaluate(const VectorXd& x, VectorXd* grad, bool keep_fixed_rows = false);
  // Diagonal of the inertia term (3n): M / h^2, or zero for a static problem.
  const VectorXd& inertia_diagonal() const { return inertia_; }
  bool is_static() const { return static_; }
  // grad E(x), the elastic part of grad = grad g(x) as Evaluate returned it,
  // on the free DoFs (fixed rows zero): grad minus the inertia, explicit
  // force and auxiliary terms (the last evaluated again; no elastic pass).
  VectorXd ElasticGradient(const VectorXd& x, const VectorXd& grad) const;
  SimulatorImpl& sim() { return sim_; }

  // An optional checkpoint of the forward solve (frictional contact's
  // screening): the first iterate with |grad g| <= abs_tolerance +
  // rel_tolerance |grad g(x0)| that does not yet meet the step's own test is
  // passed to stop(x); if it returns true the solver returns that iterate
  // (checkpoint_stopped() is then true), else it goes on, its state (e.g.
  // PD-LBFGS's curvature pairs) intact.
  struct Checkpoint {
    double abs_tolerance = 0;
    double rel_tolerance = 0;
    std::function<bool(const VectorXd& x)> stop;
  };
  void SetCheckpoint(Checkpoint checkpoint) { checkpoint_ = std::move(checkpoint); }
  // Called by the solvers with each iterate that does not meet the step's
  // test: true when it is the checkpoint's iterate and stop(x) says stop.
  bool StopAtCheckpoint(const VectorXd& x, double grad_norm, double initial_norm);
  bool checkpoint_stopped() const { return checkpoint_stopped_; }

  // The convergence test's reference |grad g(x_i + h v_i)| when the solve
  // starts elsewhere (solver/energy_bounded_step.h). ReferenceResidual(r)
  // returns it, or r (the start's own residual) when none was set.
  void SetReferenceResidual(double residual) { reference_residual_ = residual; }
  double ReferenceResidual(double start_residual) const {
    return reference_residual_ >= 0 ? reference_residual_ : start_residual;
  }
  // The estimated rounding floor of |grad g| (N): what rounding alone leaves
  // in a gradient evaluated in double precision near this step's solution,
  //   eps sqrt(sum over free DoFs d of (M_d / h^2 |xhat_d| + |f_d| + r_d)^2),
  // r_d the rounding of the elastic force at d's node: its samples'
  // (2 mu + lambda) vol |grad N| times 1 + |F|'s rounding scale from the
  // absolute positions (simulator_impl.cc, ElasticRoundingScale). The solvers
  // end a solve whose line search stalls within kRoundingFloorStall of it
  // (SolverOptions::accept_rounding_floor). Computed on first use.
  double RoundingFloor();
  // The factor: a stall with |grad g| <= kRoundingFloorStall * RoundingFloor()
  // is the floor (the stalls measured by `diffpd stress`, docs/benchmarks.md).
  static constexpr double kRoundingFloorStall = 100;

  // True, with *value = g(x), if the latest Evaluate was at exactly x.
  bool LastValueAt(const VectorXd& x, double* value) const;

 private:
  SimulatorImpl& sim_;
  VectorXd xhat_;
  VectorXd force_;
  VectorXd inertia_;
  bool static_;
  Checkpoint checkpoint_;
  bool checkpoint_done_ = false;
  bool checkpoint_stopped_ = false;
  double reference_residual_ = -1;
  double rounding_floor_ = -1;  // not computed yet
  VectorXd last_x_;             // the latest successful Evaluate's point and value
  double last_value_ = 0;
  bool have_last_ = false;
};

// Exact Hessian of one step's objective at a point, over the free DoFs,
// solved for one or several right-hand sides by the method's own machinery
// (step_linearization.cc): a direct factorisation for newton-cholesky and
// newton-ldlt, PCG for newton-pcg; for PD and PD-LBFGS the PD-preconditioned
// iteration (with a direct fallback), a direct factorisation, or either per
// step by estimated cost (SolverOptions::adjoint_solver).
class StepLinearization {
 public:
  StepLinearization(SimulatorImpl& sim, const VectorXd& x, bool static_problem = false);
  ~StepLinearization();
  // Relative residual ||H z - b|| / ||b|| of the iterative solves (default:
  // SolverOptions::backward_rel_tolerance).
  void set_rel_tolerance(double rel_tolerance) { rel_tolerance_ = rel_tolerance; }
  // The previous steps' solutions (not owned; nullptr: none): the iteration
  // starts from their Galerkin guess, and the solution is added to them.
  void set_recycling(AdjointRecycling* recycling) { recycling_ = recycling; }
  // Before the first solve: H's element pass also keeps the elastic
  // unit-parameter gradients at x for PartLameDots (one pass over the
  // elements, one SVD per sample, instead of two). Its SVDs start cold, as
  // ElasticForces::PartLameDots' do, so the dots depend on x alone.
  void KeepLameGradients() { keep_lame_gradients_ = true; }
  // The elastic forces' PartLameDots(x, z, ...) over the simulator's parts:
  // from the gradients kept by H's element pass when KeepLameGradients was
  // called before it ran, else evaluated afresh.
  void PartLameDots(const VectorXd& z, VectorXd* dmu, VectorXd* dlambda);
  // Steps of the pass still to solve, this one included (>= 1; default 1):
  // AdjointSolver::kAuto spreads the one-off analysis of H over them.
  void set_steps_left(int steps) { steps_left_ = steps < 1 ? 1 : steps; }
  // Solves H z = b (3n; fixed entries of b ignored, of z zero): one adjoint
  // step (the simulator's backward cost model, AdjointSolver::kAuto). Throws
  // SolverError(kNonFinite) for a b with a non-finite entry or a solution
  // that overflows (an adjoint or tangent beyond double precision),
  // kFactorizationFailed for a singular H.
  VectorXd Solve(const VectorXd& b, BackwardReport* report);
  // Solves H Z = B for the P columns of B (3n x P) together: PD methods
  // iterate all columns in lockstep with one batched A^{-1} solve per
  // iteration, or factorise H once; Newton methods reuse one factorisation.
  // Columns whose iteration fails fall back to the direct solve (counted
  // per column).
  MatrixXd SolveColumns(const MatrixXd& b, BackwardReport* report);
  // H z (3n, free rows only).
  VectorXd Apply(const VectorXd& z);
  // H Z for the columns of Z (3n x P) in one pass over the element
  // Hessians; column c equals Apply(Z.col(c)) bit for bit.
  MatrixXd ApplyColumns(const MatrixXd& z);
  // H z with the fixed entries of z zeroed but every row kept: the fixed rows
  // carry the coupling to the free DoFs (frictional contact's pin gradient).
  VectorXd ApplyUnmasked(const VectorXd& z);

 private:
  // The packed element Hessians at x_ (computed on first use).
  const std::vector<double>& PackedBlocks();
  // Assembles matrix_ (elastic and auxiliary blocks, inertia) once.
  void AssembleMatrix();
  // Solves by the route the method and options give (timing it into `model`
  // when the model chose it); fills the report's counts.
  MatrixXd SolveSystem(const MatrixXd& b, AdjointCostModel* model, bool tangent, BackwardReport* report);
  // The simulator's HessianFactorization of H (factorised again if another
  // solve used it since), sparse LU where H is indefinite. False for a
  // singular H; throws SolverError(kNonFinite) when z overflows.
  bool DirectSolve(const MatrixXd& b, MatrixXd* z);
  // PD methods: the estimated bytes of a factor of H, and whether a direct
  // solve may run (SolverOptions::adjoint_direct_max_bytes, or kDirect).
  static constexpr double kHessianFactorEntriesPerPdEntry = 9;
  double DirectAdjointBytes();
  bool DirectAdjointFits();
  // The PD-preconditioned iteration (options.pd_backward) on the columns of
  // b in lockstep; ok[c] tells which converged.
  void IterativeSolveColumns(const MatrixXd& b, MatrixXd* z, std::vector<char>* ok, int* iterations);
  bool PcgSolve(const VectorXd& b, VectorXd* z, int* iterations);
  // AdjointSolver::kAuto's sizes (adjoint_work.h) for a step solving `dofs`
  // unknowns.
  AdjointWorkSizes WorkSizes();

  SimulatorImpl& sim_;
  VectorXd x_;
  bool static_;
  double rel_tolerance_;
  VectorXd inertia_;
  // Element Hessians at x_ of the elastic and the auxiliary energies, not
  // projected, packed (ElasticForces::PackedElementHessians' layout): every
  // product with H and the assembled H use them.
  std::vector<double> packed_blocks_;  // SimulatorImpl::packed_hessian_storage while lent
  bool have_blocks_ = false;
  bool keep_lame_gradients_ = false;
  // The elastic unit-parameter gradients at x_ (ElasticForces::
  // PackedElementHessians), when kept; empty otherwise.
  std::vector<double> lame_gradients_;
  SparseMatrix matrix_;  // assembled exact H (lazily)
  bool have_matrix_ = false;
  bool factored_ = false;
  int factor_id_ = -1;  // HessianFactorization::num_factorizations() after ours
  AdjointRecycling* recycling_ = nullptr;
  int steps_left_ = 1;
  int hessian_products_ = 0;  // products with H so far (Apply, ApplyUnmasked)
  int pd_solves_ = 0;         // single-vector solves with A's factors so far
  std::unique_ptr<Eigen::SparseLU<SparseMatrix>> lu_;
};

// Forward solvers of one implicit step. Each returns x_{i+1} and fills the
// report; each throws SolverError when the step does not converge.
using ImplicitSolver = std::function<VectorXd(StepObjective&, const VectorXd& x0, StepReport*)>;
VectorXd NewtonSolve(StepObjective& objective, const VectorXd& x0, StepReport* report);
VectorXd PdSolve(StepObjective& objective, const VectorXd& x0, StepReport* report);
VectorXd PdLbfgsSolve(StepObjective& objective, const VectorXd& x0, StepReport* report);

// True when ||grad|| meets the common convergence test (never for a
// non-finite norm).
bool Converged(const SolverOptions& options, double grad_norm, double initial_norm);
// The per-iteration bookkeeping every forward solver shares: records
// iteration `it` (iterate x) and |grad| in the report, logs it (verbosity >=
// 2), and returns true when converged or stopped at the objective's
// checkpoint; throws SolverError(kNonFinite) when |grad| or the initial
// residual is not finite, and ThrowNotConverged's error when `it` reached
// the iteration limit without converging.
bool IterationConverged(StepObjective& objective, int it, const VectorXd& x, double grad_norm, StepReport* report);
// Adds a later solve of the same step (a re-solve from x_i, Newton after a
// PD-LBFGS stall, a contact pass) to the step's report: its iterations,
// halvings and energy restarts add up, its final residual and rounding-floor
// flag become the step's, a Newton fallback anywhere marks the step.
void AppendSolve(const StepReport& later, StepReport* report);
// Ends a solve whose line search stalled at g's rounding floor
// (LineSearchResult::at_rounding_floor): marks the report, records
// |grad g| as the final residual and returns x.
VectorXd EndAtRoundingFloor(const VectorXd& x, double grad_norm, StepReport* report);
// Throws SolverError(kMaxIterations) with a message naming method and residuals.
[[noreturn]] void ThrowNotConverged(const SolverOptions& options, int iterations, double grad_norm,
                                    double initial_norm);
// Throws SolverError(kNonFinite) if v has a non-finite entry.
void CheckFinite(const VectorXd& v, const char* what);

}  // namespace diffpd::internal
