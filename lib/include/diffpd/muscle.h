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
// a < 1 contracts, a > 1 extends. This is a projective-dynamics energy
// (w/2)|G x - p|^2 with the feature G x = F m (3-vector), w = k vol_s and the
// projection p = a F m / |F m| onto the sphere of radius a (at F m = 0 the
// fibre direction m is used), so PD solves it with the constant matrix A
// (activation does not enter A) and Newton with its exact Hessian.
// Gradients w.r.t. the activations: RolloutGradient::activation.
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
