// Options of the time integrators and their derivatives. Plain struct with
// documented defaults; Validate() throws InvalidInputError on a bad value.
#pragma once

#include <string>

namespace diffpd {

enum class Method {
  kSemiImplicit,    // symplectic Euler: explicit, needs a small time step
  kNewtonCholesky,  // implicit Euler, Newton + CHOLMOD supernodal Cholesky
  kNewtonPcg,       // implicit Euler, Newton + preconditioned conjugate gradients
  kPd,              // implicit Euler, projective dynamics (local-global)
  kPdLbfgs,         // implicit Euler, L-BFGS with the PD matrix as initial Hessian
  // Implicit Euler, Newton + simplicial LDL^T under AMD ordering (Eigen),
  // ordered and analysed at every solve: the DiffPD paper's Newton baseline,
  // for reproducing its speed-ups like for like (newton-cholesky is faster).
  kNewtonLdlt,
};
// "semi-implicit", "newton-cholesky", "newton-pcg", "pd", "pd-lbfgs",
// "newton-ldlt".
const char* ToString(Method method);
// Inverse of ToString; throws InvalidInputError listing the valid names.
Method ParseMethod(const std::string& name);

enum class PcgPreconditioner { kJacobi, kIncompleteCholesky };

// What the relative tolerance of each step's solve is relative to.
enum class ToleranceReference {
  // |grad g(x_i + h v_i)|: the residual where the solve starts.
  kStartResidual,
  // |(M / h^2)(x_i + h v_i) + f| over the free DoFs (f the step's explicit
  // force; (M / h^2) times the inertial prediction): the DiffPD reference
  // code's test. It grows with the body's distance from the origin and is
  // usually far larger than the start residual (a looser test at the same
  // rel_tolerance).
  kInertia,
};

// How the PD backward solves hess g z = b with the forward factor of A.
enum class PdBackwardMethod {
  kFixedPoint,  // A z_{k+1} = b + dA z_k, the DiffPD iteration
  kLbfgs,       // L-BFGS on 1/2 z^T H z - b^T z, A as initial Hessian, exact steps
  // Conjugate gradients preconditioned by A^{-1}: the same iterates as kLbfgs
  // in exact arithmetic (exact steps on a quadratic), without its two-loop
  // recursion's 4 * lbfgs_history vector passes per iteration.
  kConjugateGradient,
};

// How the backward (adjoint) and tangent passes of the PD methods (pd,
// pd-lbfgs) solve with the step Hessian H. Newton methods always use their
// own linear solver (a factorisation of H, or PCG for newton-pcg).
enum class AdjointSolver {
  // Per step, whichever of the two below is estimated cheaper on this
  // problem (the factorisation only when more than 10% cheaper). The estimates are deterministic, from counts and
  // sizes, never
  // from clocks: the iteration's from the Hessian products, factor solves
  // and iterations its latest step made, the factorisation's from its
  // factor's entries and flop count (estimated from A's before its first
  // symbolic analysis, whose one-off cost is spread over the pass's
  // remaining steps), with per-operation costs of one reference core. The
  // first step iterates; no factorisation is made only to be measured; while
  // the factorisation leads, the iteration is counted again after max(8,
  // (r - 1) / 0.05) direct steps (r: the ratio of the estimates; <= 5%
  // extra). The iteration's estimate persists across Backward/Tangents calls
  // of one simulator (SetOptions resets it). The same problem makes the same
  // choices on every run. Which steps used which is reported
  // (BackwardReport); the gradients agree with either to the adjoint's
  // tolerance.
  kAuto,
  // The PD-preconditioned iteration (pd_backward), falling back to a direct
  // solve when it fails.
  kIterative,
  // A sparse Cholesky factorisation of the assembled H (CHOLMOD; ordering
  // and symbolic analysis once per simulator, numeric factorisation per
  // step), sparse LU where H is indefinite.
  kDirect,
};
// "auto", "iterative", "direct".
const char* ToString(AdjointSolver solver);
// Inverse of ToString; throws InvalidInputError listing the valid names.
AdjointSolver ParseAdjointSolver(const std::string& name);

struct SolverOptions {
  Method method = Method::kPd;
  // Time step h, seconds; > 0.
  double time_step = 0.01;

  // Convergence of each implicit step, the same test for every method:
  //   ||grad g(x)||_2 <= abs_tolerance + rel_tolerance * ||grad g(x0)||_2,
  // over the free DoFs, x0 = x_i + h v_i, whichever start the solve takes.
  double abs_tolerance = 1e-9;  // N
  double rel_tolerance = 1e-6;
  // The norm rel_tolerance multiplies (the first line's |grad g(x0)|);
  // StepReport::initial_residual reports it.
  ToleranceReference tolerance_reference = ToleranceReference::kStartResidual;
  int max_iterations = 1000;  // per step (Newton or PD iterations)
  // After a step's solve from x0, compare g there with g(x_i), the previous
  // total energy (kinetic + elastic + the explicit forces' potential); if the
  // result is above it (a far stationary point, which a very stiff, nearly
  // incompressible body at a large h can reach), solve again from x_i, so
  // that the step's potential energy never
  // exceeds the previous total energy. Costs one evaluation of g per step;
  // other steps' results are unchanged. With frictional contact each
  // active-set pass is checked against x_i with that pass's pins (the bound
  // then holds for the pinned problem). false: no check.
  bool bound_step_energy = true;

  // Backtracking (Armijo) line search of Newton and PD-LBFGS.
  double armijo_c = 1e-4;
  int max_line_search_steps = 40;
  // A line search that finds no acceptable step while ||grad g|| is within
  // 100 times g's estimated rounding floor (eps times the magnitudes of the
  // inertia, explicit-force and elastic-stress terms) cannot do better in
  // double precision: true ends the step there, as
  // converged at the floor (StepReport::rounding_floor_stop); false throws
  // SolverError(kLineSearchFailed) as for any other stall. Only steps that
  // would otherwise fail are affected (very stiff material, tolerances below
  // the floor).
  bool accept_rounding_floor = true;

  // Newton-PCG: the linear solve stops at relative residual pcg_rel_tolerance
  // (relative to the right-hand side) or after pcg_max_iterations.
  PcgPreconditioner pcg_preconditioner = PcgPreconditioner::kIncompleteCholesky;
  double pcg_rel_tolerance = 1e-8;
  int pcg_max_iterations = 20000;

  // PD-LBFGS and the PD backward's L-BFGS (PdBackwardMethod::kLbfgs): number
  // of stored curvature pairs; >= 1. Memory: 2 x lbfgs_history x 3n doubles.
  int lbfgs_history = 20;
  // PD-LBFGS (forward and backward): its initial Hessian is the PD matrix A
  // with the elastic weights w (2 mu + lambda for pd-corotated + pd-volume)
  // multiplied by this factor; M / h^2 and muscle/penalty terms are not
  // scaled. Any factor in (0, 1] gives the same converged result (A is only
  // the L-BFGS preconditioner); 1 is the DiffPD matrix. A has full stiffness
  // on rotations and volume change while the true Hessian has none on
  // rotations, so a smaller factor preconditions bending better; much
  // smaller factors under-weight volume change and converge slowly again.
  // Must be in (0, 1]. The plain `pd`
  // method always uses 1 (its fixed point needs the true A). With a factor
  // < 1 the fixed-point backward (PdBackwardMethod::kFixedPoint) may not
  // converge and then falls back to a direct solve; the kLbfgs and default
  // kConjugateGradient backwards converge for any factor (H positive definite).
  double lbfgs_weight_scale = 0.3;
  // PD-LBFGS: when the line search stalls (no acceptable step along the
  // quasi-Newton direction nor the plain PD one) above the rounding-floor
  // band (accept_rounding_floor), or the step reaches max_iterations, it goes
  // on with Newton iterations (projected Hessian, CHOLMOD; at most
  // max_iterations more) from where it stopped, to the same test
  // (StepReport::newton_fallback). Stiff or nearly incompressible material
  // at large h, where g can no longer resolve PD-LBFGS's progress or
  // PD-LBFGS needs close to max_iterations; ordinary steps never get there.
  // false: the stall or the iteration limit is an error
  // (SolverError(kLineSearchFailed) or SolverError(kMaxIterations)).
  bool pd_lbfgs_newton_fallback = true;
  // For a body without Dirichlet DoFs (free to move: on frictional or
  // penalty contact, swimming, falling), PD-LBFGS's initial inverse Hessian
  // and the PD backward's preconditioner (CG and L-BFGS, and the tangent
  // passes; not the DiffPD fixed point nor the plain `pd` forward) add a
  // coarse correction for its 6 rigid modes: A^-1 r + Z (Z^T H Z)^+ Z^T r,
  // Z the translations and rotations (zero at contact pins), H the step
  // Hessian at the solve's start. A charges a rigid rotation like a stretch
  // while H resists it with inertia alone, so free bodies converge slowly
  // without it. Costs per solve the Hessians of the elements at contact pins
  // (forward; grad E comes from the solve's first gradient) or 6 Hessian
  // products (backward), and 12 vector passes per iteration. Bodies with
  // Dirichlet DoFs never use it (their cut rigid modes are not soft).
  // Dynamic steps only. Only the preconditioner changes, not the test a
  // step must meet.
  bool rigid_mode_correction = true;

  // PD methods' backward and tangent solves: iterative, direct or chosen per step by estimated cost (AdjointSolver).
  AdjointSolver adjoint_solver = AdjointSolver::kAuto;
  PdBackwardMethod pd_backward = PdBackwardMethod::kConjugateGradient;
  // Iterative backward (adjoint) and tangent solves stop at the relative
  // residual ||H z - b|| / ||b|| <= backward_rel_tolerance, in [0, 1);
  // 0 (default): per step, backward_tolerance_factor (in (0, 1]) times the
  // relative residual that step's forward solve reached (final / initial,
  // at most the forward's rel_tolerance), not below 1e-12. An adjoint solved
  // far tighter than the forward buys no gradient accuracy, one much looser
  // loses it; with the default factor the gradient stays within 1.5x of the
  // error an exact adjoint gives at the same forward tolerance on the tests'
  // beam (benchmarks/backward_benchmark --sweep measures the front on other
  // scenes). A direct adjoint solve is exact whatever the tolerance.
  double backward_rel_tolerance = 0;
  double backward_tolerance_factor = 0.01;
  int backward_max_iterations = 1000;
  // PD methods' iterative backward and tangent solves start from the
  // Galerkin projection of the step's system onto the span of the latest
  // this-many solutions of earlier steps (consecutive adjoints are close),
  // at the cost of as many Hessian products per step; >= 0, 0: from zero.
  int adjoint_guess_solutions = 8;

  // A step fails with SolverError(kDiverged) when the body's extent (the
  // diagonal of its nodes' bounding box) exceeds max_extent_ratio times its
  // rest extent. Rigid motion keeps the extent (a rotation changes it by at
  // most sqrt(3)), and solids do not stretch a thousandfold, while an
  // unstable step tears the nodes apart geometrically (semi-implicit Euler
  // at h = 1e3 s: 1e17 m within three steps; at h = 0.01 s on a stiff beam,
  // kilometres within 0.06 s), so the error comes early instead of as a
  // NaN, or never. Velocities need no bound of their own, v_{i+1} = (x_{i+1}
  // - x_i) / h. > 1; infinity: only a non-finite state is an error.
  double max_extent_ratio = 1e3;

  // PD methods solve with their factor of A through a copy of it laid out
  // for parallel triangular solves (twice L's entries: about 20 bytes per
  // entry, 1.2 GiB for a 421 k-DoF cantilever). When that copy's estimated
  // size exceeds this many bytes the copy is not made and CHOLMOD's own
  // solves serve instead (the same solutions to rounding; slower on two or
  // more threads, serial). Default 4 GiB, a fixed size so that which path
  // runs never depends on the machine's state; >= 0 (0: never a copy,
  // infinity: always). Simulator::pd_factor_copy_bytes() says which path is
  // in use.
  double pd_factor_copy_max_bytes = 4294967296.0;

  // The PD methods' direct adjoint and tangent solves factorise the 3n x 3n
  // step Hessian H, whose factor holds about 9 times the entries of the PD
  // factor (3 x 3 blocks per node pair; 8 bytes each): 18 GiB on a
  // million-DoF beam. When that estimate exceeds this many bytes, kAuto
  // keeps to the iteration (the direct solve is neither timed nor used) and
  // an iterative solve that fails raises SolverError(kMaxIterations) naming
  // this bound instead of falling back to a factorisation that may not fit
  // in memory; kDirect is always honoured. Default 8 GiB, fixed for the same
  // reason as the copy's bound; >= 0 (0: never a direct PD adjoint unless
  // kDirect, infinity: no bound).
  double adjoint_direct_max_bytes = 8589934592.0;

  // Each SVD of the elastic forces (one per quadrature sample) starts its
  // iterations from the previous evaluation's result at that sample (true,
  // default: fewer sweeps) or, false, from the identity at the start of
  // every forward step, backward step and tangent step, so that a step
  // depends on its states and input alone and is recomputed bit for bit.
  // The results differ in the last bits only. Checkpointed rollouts
  // (Simulator::SimulateCheckpointed) always run with false; a stored
  // rollout made with false has their derivatives bit for bit.
  bool svd_warm_start = true;

  // Threads for the element loops and PD's triangular solves (0: OpenMP's
  // default), at most MaxSolverThreads(). Never changes the process-wide
  // OpenMP setting. Results do not depend on it beyond rounding (the solves'
  // sums run in another order).
  int num_threads = 0;
  // 0: silent; 1: one line per step on stderr; 2: one line per iteration.
  int verbosity = 0;

  // Throws InvalidInputError naming the field, its value and the valid range
  // ("solver options: time_step = -1 is invalid: must be finite and > 0
  // (s)"), also for an enum field holding no declared value (an integer cast
  // to the enum).
  void Validate() const;
};

// The most threads SolverOptions::num_threads may ask for: 4 x the
// processors OpenMP reports (omp_get_num_procs()). More never speeds up a
// step, and tens of thousands make the OpenMP runtime fail.
int MaxSolverThreads();

}  // namespace diffpd
