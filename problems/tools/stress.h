// `diffpd stress`: stability at the extremes. Runs problems over a grid of
// Young's modulus, Poisson's ratio and time step with each method and
// classifies every case:
//
//  - "ok": every step returned finite states; the total energy
//      T = 1/2 v^T M v + E_elastic(x) - sum_i m_i g . x_i
//    (gravity's work is the drop of its potential) never rose above its
//    initial value by more than energy_tolerance * (the magnitude of the
//    energies involved, see StressCase::max_energy_excess), as implicit Euler
//    only dissipates; the backward pass of the whole rollout returned finite
//    gradients; and on the first gradcheck_steps steps the reverse-mode
//    gradient passes CheckStressGradient (below; solves at rel_tolerance
//    1e-10, above the rounding floor) within gradcheck_tolerance;
//  - "failed": a SolverError stopped the rollout, its backward pass or the
//    gradient check; `message` carries its status, its text and where;
//  - "violation": anything else (a non-finite value returned without an
//    error, energy growth, a gradient that disagrees with finite differences,
//    an unexpected exception). A violation is a bug in the library.
#pragma once

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
  int refine = -6;   // its doublings (bench.h): -6 is 8x2x2 cantilever, 2^3 cube
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
  int gradcheck_steps = 3;  // prefix checked by finite differences (0: skip)
  // Allowed relative error of the check (CheckStressGradient's tolerance).
  double gradcheck_tolerance = 1e-4;
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
  std::string outcome;  // "ok", "failed" or "violation"
  std::string message;  // empty for ok; the error or the violated property
  int steps_completed = 0;
  // Steps of the rollout that ended at g's rounding floor above the
  // tolerance (StepReport::rounding_floor_stop), and PD-LBFGS steps that
  // Newton finished after a line-search stall (StepReport::newton_fallback).
  int rounding_floor_steps = 0;
  int newton_fallback_steps = 0;
  // max over steps of (T_k - T_0) / (|T_0 parts| + |T_k parts| + 1e-300),
  // where the parts are kinetic, elastic and gravitational (relative to T_0).
  double max_energy_excess = 0;
  double gradcheck_error = 0;  // max relative error of the check (0 if not run)
  // Inputs the check could not resolve above the noise (see StressGradientCheck).
  std::vector<std::string> gradcheck_unresolved;
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

// Directional central-difference check of the reverse-mode gradient of
// L = c_x . x_K + c_v . v_K (c ~ N(0,1), `seed`) over `steps` steps from
// `initial` with no external force, for x0, v0, the per-step external forces,
// E, nu and rho. Each input moves along a random direction in units of its
// scale (x0: the body's size s; v0: s / h; forces: m_i s / h^2; E, rho:
// relative; nu: min(0.1, (0.5 - nu) / 2)), by e = 1e-2, 1e-3, .., 1e-7; the error of
// an input is the smallest over e of
//   |fd - g.d| / max(|fd|, |g.d|).
// An input passes when that is <= tolerance (agreement to 1e-4 is no
// coincidence); above it, the input fails only if some step e resolves the
// derivative to that tolerance, i.e. its noise estimate
//   noise / e <= tolerance * max(|fd|, |g.d|),
// noise = 1e-13 (sum |c_x,i x_i| + |c_v,i| (|v_i| + |x_i| / h)) (rounding of
// the loss) + (|c_x| + |c_v| / h) sum_k r_k h^2 / m_min (the loss error the
// solves leave, r_k = 10 x the final residual of step k of the unperturbed
// rollout; perturbed rollouts stop at similar residuals). Trying
// several steps finds the window between truncation and rounding that a
// fixed step misses at the grid's extremes; a wrong gradient disagrees at
// every step. An input that disagrees and has no resolved step (its effect
// on L within the noise, e.g. E for a nearly rigid body over 3 steps) is
// reported as unresolved: not tested, and not in max_error.
// One central difference of a directional derivative: step e, value
// (L(+e) - L(-e)) / 2e and an estimate of its error from noise (absolute).
struct FiniteDifference {
  double step = 0;
  double value = 0;
  double noise = 0;
};
struct DerivativeVerdict {
  double error = 0;     // min over the differences of |value - analytic| / max(|value|, |analytic|)
  bool tested = false;  // false: the derivative disagrees but is within the noise at every step
};
// The rule of CheckStressGradient below for one derivative.
DerivativeVerdict JudgeDerivative(double analytic, const std::vector<FiniteDifference>& differences, double tolerance);

struct StressGradientCheck {
  std::vector<std::string> inputs;  // "x0", "v0", "external_force", ...
  std::vector<double> errors;       // per input, smallest over the steps
  std::vector<bool> resolved;       // per input: false = unresolved (untested)
  double max_error = 0;
};
// Throws SolverError from the solves (use tight options).
StressGradientCheck CheckStressGradient(const Scene& scene, const SolverOptions& options, const State& initial,
                                        int steps, std::uint64_t seed, double tolerance = 1e-4);

// Runs one case; a line every 10 s of a long rollout goes to `progress`
// (nullptr: silent).
StressCase RunStressCase(const StressProblem& problem, Method method, double youngs_modulus, double poissons_ratio,
                         double time_step, const StressOptions& options, std::ostream* progress = nullptr);

// Runs the whole grid (problems x methods x E x nu x h), one progress line per
// case on `progress` (nullptr: silent). Throws InvalidInputError on bad options.
std::vector<StressCase> RunStress(const StressOptions& options, std::ostream* progress = nullptr);

// JSON list of the cases (fields as in StressCase).
nlohmann::json StressToJson(const std::vector<StressCase>& cases);

}  // namespace diffpd::problems
