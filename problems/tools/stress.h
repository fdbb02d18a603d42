// `diffpd stress`: stability at the extremes. Runs problems over a grid of
// Young's modulus, Poisson's ratio and time step with each method and
// classifies every case:
//
//  - "ok": every step returned finite states; the total energy
//      T = 1/2 v^T M v + E_elastic(x) - sum_i m_i g . x_i
//    (gravity's work is the drop of its potential) never rose above its
//    initial value by more than energy_tolerance * (the magnitude of the
//    energies involved, see StressCase::max_energy_excess), as implicit Euler
//    only dissipates (scenes with frictional contact: contact_energy_tolerance,
//    see there); the backward pass of the whole rollout returned finite
//    gradients; and on the first gradcheck_steps steps (long cases: the last
//    ones, from the rollout's state there) the reverse-mode
//    gradient passes CheckRolloutGradient (gradcheck.h: one direction per
//    input kind, six steps (two more where needed), the forward-mode tangent
//    where the differences cannot decide, the Newton-Cholesky reference for
//    the iterative methods; solves at rel_tolerance gradcheck_rel_tolerance)
//    within gradcheck_tolerance, or is unresolved (listed, not a violation);
//  - "failed": a SolverError stopped the rollout, its backward pass or the
//    gradient check; `message` carries its status, its text and where;
//  - "violation": anything else (a non-finite value returned without an
//    error, energy growth, a gradient that disagrees with finite differences,
//    an unexpected exception). A violation is a bug in the library.
#pragma once

#include <array>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/solver_options.h"

namespace diffpd::problems {

struct StressProblem {
  std::string name;  // a problem MakeRefinedProblem accepts
  // Its doublings (bench.h): -6 is the 8x2x2 cantilever, the 2^3 cube, the
  // bouncing ball's 2^3 voxels and the rolling sphere's 19; -9 the 4x1x1
  // cantilever and a single cell of the others.
  int refine = -6;
};

struct StressOptions {
  std::vector<StressProblem> problems = {{"cantilever", -6}, {"falling-cube", -6}};
  std::vector<Method> methods = {Method::kPd, Method::kPdLbfgs, Method::kNewtonPcg, Method::kNewtonCholesky};
  std::vector<double> youngs_moduli = {1e2, 1e4, 1e6, 1e8, 1e10};  // Pa
  std::vector<double> poissons_ratios = {0, 0.3, 0.45, 0.499};
  std::vector<double> time_steps = {1e-5, 1e-3, 1e-2, 1e-1};  // s
  int steps = 10000;                                          // per case
  double rel_tolerance = 1e-6;                                // of each step (SolverOptions::rel_tolerance)
  // Of each step (N); <= 0: AutoAbsTolerance(scene, h), above the rounding floor.
  double abs_tolerance = -1;
  int max_iterations = 1000;  // of each step (SolverOptions::max_iterations)
  int threads = 0;
  // Allowed rise of the total energy, relative to its magnitude, for the
  // implicit methods (implicit Euler dissipates: measured rises are 0).
  double energy_tolerance = 1e-6;
  // The same for semi-implicit, which does not dissipate: symplectic Euler's
  // energy oscillates by O(h omega) when stable; a rise above half the
  // energy scale (the measure tends to 1 as energy explodes) is instability.
  double explicit_energy_tolerance = 0.5;
  // The same for scenes with frictional contact (contact.h). Friction
  // dissipates (a pinned node sticks), but a node is pinned where its
  // previous position projects onto the surface, not where the unconstrained
  // step would put it: the previous state violates the new pins, so the
  // argument that bounds an implicit step's energy by the previous one does
  // not hold exactly; the pins move a landing node by up to the gap it
  // closes in one step, and a penetrating one back out (see
  // docs/benchmarks.md for the measured rises).
  double contact_energy_tolerance = 1e-6;
  // Long rollouts: > 0 adds, for each problem and method, the grid's
  // extreme corners (smallest and largest E, nu, h, as the half of the 2^3
  // corners in which every pair of axes meets its four combinations) run for
  // this many steps, the gradient checked on their last gradcheck_steps
  // steps; 0: none.
  int long_steps = 0;
  // Only the long cases (long_steps > 0), not the grid.
  bool long_only = false;
  int gradcheck_steps = 3;  // prefix checked by finite differences (0: skip)
  // Relative tolerance of the check's verdicts (GradCheckOptions::tolerance).
  double gradcheck_tolerance = 1e-4;
  // Solve tolerance of the check's rollouts: tight, so that the differences'
  // noise floor stays well below gradcheck_tolerance.
  double gradcheck_rel_tolerance = 1e-11;
  std::uint64_t seed = 20211;
  // SolverOptions::rigid_mode_correction of every case (used by PD-LBFGS and
  // the PD backward on bodies without Dirichlet DoFs: the falling cube).
  bool rigid_mode_correction = true;

  // Throws InvalidInputError naming the field, its value and the valid range.
  void Validate() const;
};

struct StressCase {
  std::string problem;
  std::string method;
  double youngs_modulus = 0, poissons_ratio = 0, time_step = 0;
  int steps = 0;           // requested (StressOptions::steps, or long_steps for a long case)
  bool long_case = false;  // one of the long cases (StressOptions::long_steps)
  std::string outcome;     // "ok", "failed" or "violation"
  std::string message;     // empty for ok; the error or the violated property
  int steps_completed = 0;
  // Steps of the rollout that ended at g's rounding floor above the
  // tolerance (StepReport::rounding_floor_stop), and PD-LBFGS steps that
  // Newton finished after a line-search stall (StepReport::newton_fallback).
  int rounding_floor_steps = 0;
  int newton_fallback_steps = 0;
  // Frictional contact: steps that ended with a non-empty active set, and
  // the largest active set (nodes); 0 for scenes without it.
  int contact_steps = 0;
  int max_contact_nodes = 0;
  // max over steps of (T_k - T_0) / (|T_0 parts| + |T_k parts| + 1e-300),
  // where the parts are kinetic, elastic and gravitational (relative to T_0).
  double max_energy_excess = 0;
  // The gradient check (gradcheck.h; zeros and empty when not run): the
  // largest relative error on each resolved input's basis (against the
  // differences, or the forward-mode tangent where it decided) and the
  // largest noise floor of the differences, the smallest margin over the
  // resolved inputs (infinite when none), the inputs it could not resolve
  // and those the tangent decided (the differences could not). Whether the
  // Newton-Cholesky reference was compared (iterative methods), and why not
  // where its rollout failed or reached another solution.
  bool gradcheck_run = false;
  double gradcheck_error = 0;
  double gradcheck_floor = 0;
  double gradcheck_margin = 0;
  std::vector<std::string> gradcheck_unresolved;
  std::vector<std::string> gradcheck_tangent;
  // Inputs that passed although the reference disagreed, because the
  // method's gradient with its forward 100x tighter agrees with it
  // (GradCheckInput::tightened_reference_error).
  std::vector<std::string> gradcheck_tightened;
  bool gradcheck_reference = false;
  std::string gradcheck_reference_failure;
  double seconds = 0;
};

// An absolute tolerance on |grad g| (N) ten times an estimate of its
// rounding floor, never below the library default 1e-9: the floor is
// machine epsilon times the largest terms that cancel in grad g, the
// inertia term M (x - y) / h^2 ~ m |x| / h^2 (m = rho V / #nodes over the
// rest bounding box V) and the elastic forces ~ (2 mu + lambda) A sqrt(3n)
// (A an element's face area; lambda grows without bound as nu -> 0.5). With
// 1e-9 N the solvers stop with "line search failed" near E = 1e10 Pa or
// h = 1e-5 s. The floor grows with |x|: a body far from the origin (a cube
// falling for minutes) can still reach it.
double AutoAbsTolerance(const Scene& scene, double time_step);

// Runs one case of options.steps steps (steps > 0: that many, the gradient
// then checked on the last gradcheck_steps steps); a line every 10 s of a long
// rollout goes to `progress` (nullptr: silent).
StressCase RunStressCase(const StressProblem& problem, Method method, double youngs_modulus, double poissons_ratio,
                         double time_step, const StressOptions& options, std::ostream* progress = nullptr,
                         int steps = 0);

// The long cases' (E, nu, h): the grid's extreme corners as described at
// StressOptions::long_steps, without repeats (fewer where an axis has one value).
std::vector<std::array<double, 3>> LongCaseCorners(const StressOptions& options);

// Runs the whole grid (problems x methods x E x nu x h), then the long cases
// (StressOptions::long_steps), one progress line per case on `progress`
// (nullptr: silent). Throws InvalidInputError on bad options.
std::vector<StressCase> RunStress(const StressOptions& options, std::ostream* progress = nullptr);

// Summary of a grid: case counts per outcome, the cases whose gradient check
// ran, left inputs unresolved, and the smallest margin of a resolved input.
struct StressSummary {
  int cases = 0, ok = 0, failed = 0, violations = 0;
  int gradchecks = 0, unresolved_cases = 0;
  int tangent_cases = 0;            // checks where the tangent decided some input
  int long_cases = 0;               // cases longer than the grid's (StressOptions::long_steps)
  int contact_cases = 0;            // cases with at least one step in frictional contact
  double min_gradcheck_margin = 0;  // infinite when no input was resolved
};
StressSummary SummarizeStress(const std::vector<StressCase>& cases);

// JSON list of the cases (fields as in StressCase; infinite margins as null).
nlohmann::json StressToJson(const std::vector<StressCase>& cases);

}  // namespace diffpd::problems
