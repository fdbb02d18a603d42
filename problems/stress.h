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
//    gradient passes CheckRolloutGradient (gradcheck.h, central differences,
//    solves at rel_tolerance 1e-10) within gradcheck_tolerance;
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
  std::vector<double> time_steps = {1e-5, 1e-3, 1e-2, 1e-1};      // s
  int steps = 10000;             // per case
  double rel_tolerance = 1e-6;   // of each step (SolverOptions::rel_tolerance)
  int max_iterations = 1000;     // of each step (SolverOptions::max_iterations)
  int threads = 0;
  // Allowed rise of the total energy, relative to its magnitude.
  double energy_tolerance = 1e-6;
  int gradcheck_steps = 3;       // prefix checked by finite differences (0: skip)
  double gradcheck_tolerance = 1e-4;
  std::uint64_t seed = 20211;

  // Throws InvalidInputError naming the field, its value and the valid range.
  void Validate() const;
};

struct StressCase {
  std::string problem;
  std::string method;
  double youngs_modulus = 0, poissons_ratio = 0, time_step = 0;
  std::string outcome;   // "ok", "failed" or "violation"
  std::string message;   // empty for ok; the error or the violated property
  int steps_completed = 0;
  // max over steps of (T_k - T_0) / (|T_0 parts| + |T_k parts| + 1e-300),
  // where the parts are kinetic, elastic and gravitational (relative to T_0).
  double max_energy_excess = 0;
  double gradcheck_error = 0;  // max relative error of the check (0 if not run)
  double seconds = 0;
};

// Runs one case.
StressCase RunStressCase(const StressProblem& problem, Method method, double youngs_modulus, double poissons_ratio,
                         double time_step, const StressOptions& options);

// Runs the whole grid (problems x methods x E x nu x h), one progress line per
// case on `progress` (nullptr: silent). Throws InvalidInputError on bad options.
std::vector<StressCase> RunStress(const StressOptions& options, std::ostream* progress = nullptr);

// JSON list of the cases (fields as in StressCase).
nlohmann::json StressToJson(const std::vector<StressCase>& cases);

}  // namespace diffpd::problems
