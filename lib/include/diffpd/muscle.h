// Muscle fibres: actuators that contract chosen elements along a fibre
// direction (DiffPD Sec. 5, "actuation").
//
// A Muscle is one actuator: a group of elements, each with a fibre direction
// m (rest frame; normalised by the simulator), driven by one activation a per
// time step (StepInput::activation). At every quadrature sample s of its
// elements it adds the energy
//
//   E_s(x) = (k / 2) vol_s (|F_s m| - a)^2,
//
// F_s the deformation gradient and vol_s the sample's rest volume (m^3), k the
// stiffness (Pa). a = 1 is the rest length of the fibre (no force at rest),
// a < 1 contracts, a > 1 extends; a <= 0 pulls the fibre toward zero length,
// the harder the more negative a is (the energy is then (|F m| + |a|)^2).
// This is a projective-dynamics energy (w/2)|G x - p|^2 with the feature
// G x = F m (3-vector), w = k vol_s and the projection p = a F m / |F m| onto
// the sphere of radius a (at F m = 0 the fibre direction m is used), so PD
// solves it with the constant matrix A (activation does not enter A) and
// Newton with its exact Hessian.
// Gradients w.r.t. the activations: RolloutGradient::activation.
//
// Scene::Validate rejects, with InvalidInputError (j, t indices):
//   "scene: muscles[j] has no elements",
//   "scene: muscles[j].elements[t] = 99 is out of range [0, 40) (no such element)",
//   "scene: muscles[j] has 3 fibre directions for 2 elements (need one per element or a single shared one)",
//   "scene: muscles[j].fibers[t] = (0, 0, 0) is invalid: must be finite with non-zero length",
//   "scene: muscles[j].stiffness = -1 is invalid: must be finite and > 0 (Pa)".
// Step rejects a StepInput::activation of the wrong size or with a
// non-finite entry:
//   "activation has 3 entries, expected 2 (one per muscle)",
//   "activation[1] = nan is invalid: must be finite".
#pragma once

#include <vector>

#include "diffpd/types.h"

namespace diffpd {

struct Muscle {
  // Element indices in [0, mesh.num_elements()); an element may belong to
  // several muscles (their energies add up).
  std::vector<int> elements;
  // Fibre directions in the rest configuration: one per element (same order),
  // or a single one shared by all elements. Finite, non-zero length; only the
  // direction matters.
  std::vector<Vec3> fibers;
  // k, Pa; finite and > 0.
  double stiffness = 1e6;
};

}  // namespace diffpd
