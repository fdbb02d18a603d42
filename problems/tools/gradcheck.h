// Central finite-difference check of a rollout's reverse-mode gradient.
//
// Loss: L = c_x . x_K + c_v . v_K with c_x, c_v fixed pseudo-random vectors
// (seed `seed`). For each input kind (initial positions, initial velocities,
// per-step external forces, Young's modulus, Poisson's ratio, density) and
// each of `directions` random directions d, compares dL/dtheta . d with
//   (L(theta + eps d) - L(theta - eps d)) / (2 eps).
// Scenes that declare them add: "activation" (per-step muscle activations,
// baseline 0.9 + 0.02 N(0,1)), "linear_damping", the hydrodynamic parameters
// "fluid_density", "drag_tangential", "drag_normal", "thrust", and
// "penalty_friction" (all penalty contacts' mu along one direction).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "diffpd/rollout.h"
#include "diffpd/scene.h"
#include "diffpd/solver_options.h"

namespace diffpd::problems {

struct GradCheckOptions {
  int directions = 2;          // random directions per input kind
  std::uint64_t seed = 20211;  // seed of the loss and the directions
  // Relative finite-difference step: eps = relative_step * typical scale of
  // the input (1 for positions in m, velocities in m/s, forces scaled by the
  // gravity force of a node; E, rho relative; nu absolute).
  double relative_step = 1e-5;
};

struct GradCheckEntry {
  std::string input;  // "x0", "v0", "external_force", "youngs_modulus", ...
  double max_rel_error = 0;
  long entries = 0;  // number of scalar inputs of this kind
  int directions = 0;
};

struct GradCheckResult {
  std::vector<GradCheckEntry> inputs;
  double max_rel_error = 0;
};

// Runs the check; the solver options are used as given (make tolerances
// tight: the finite differences are only as good as the forward solves).
GradCheckResult CheckRolloutGradient(const Scene& scene, const SolverOptions& options, const State& initial, int steps,
                                     const GradCheckOptions& check = GradCheckOptions());

}  // namespace diffpd::problems
