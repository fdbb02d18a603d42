// Fused energy-and-gradient kernel of one hexahedron for the PD energies
// (internal): the hot loop of every PD and PD-LBFGS iteration.
//
// For a scene whose energies are pd-corotated and/or pd-volume only, the
// density at a sample with signed SVD F = U diag(sigma) V^T is
//   Psi = (w_rot / 2) |sigma - 1|^2 + (w_vol / 2) |sigma - d|^2,
//   P   = U diag(w_rot (sigma - 1) + w_vol (sigma - d)) V^T,
// with d the unit-determinant projection of sigma, w_rot = 2 mu per declared
// pd-corotated and w_vol = lambda per declared pd-volume (density_kernels.h).
// The kernel keeps the samples of kPdHexBatch elements (8 each) lane by lane
// (structure of arrays) from the deformation gradients through the SVDs and
// projections to the nodal forces, instead of packing and unpacking 3x3 matrices around each batched
// stage; the results equal the general path's (EvaluateDensity per sample) up
// to rounding.
#pragma once

#include "diffpd/types.h"

namespace diffpd::internal {

// Shape-function gradients of one hexahedron's 8 samples, lane by lane:
// entry (a, c) = dN_a/dX_c of sample l at [(a + 8 c) * 8 + l] (192 doubles).
constexpr int kHexLaneGradients = 192;

struct PdHexWeights {
  double rotation = 0;  // w_rot (Pa)
  double volume = 0;    // w_vol (Pa); 0: no volume term (no projection)
};

// One element's inputs and outputs (pointers not owned, not retained).
struct PdHexElement {
  const double* xe = nullptr;              // 3 x 8 nodal positions (m), column-major
  const double* lane_gradients = nullptr;  // kHexLaneGradients (1/m)
  const double* grads = nullptr;           // the same in sample order: FemModel::grad of its first sample
  const double* sample_volume = nullptr;   // 8 sample volumes (m^3)
  PdHexWeights weights;
  Mat3* v_cache = nullptr;   // 8 samples' last V: warm start, written back
  double* fe = nullptr;      // out: 3 x 8 nodal forces dE_e/dx_e (N), column-major
  double* energy = nullptr;  // out: E_e (J)
};

// Elements per call: two hexahedra fill one SVD batch (svd3.h), whose lanes
// then carry two independent dependency chains (the sweeps' square roots and
// divisions are latency-bound).
constexpr int kPdHexBatch = 2;

// Evaluates `count` (1..kPdHexBatch) elements and returns true; returns
// false and changes nothing when a sample's F is not finite, is zero or has
// entries outside [1e-100, 1e100] in magnitude (the caller then takes the
// general path, which reports or rescales them).
bool PdHexEnergyAndForces(const PdHexElement* elements, int count);

}  // namespace diffpd::internal
