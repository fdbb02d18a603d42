// Packed symmetric element matrices, interleaved across elements (internal):
// the storage of the element Hessians that the PD adjoint iteration
// multiplies with tens of times per step.
//
// Layout: elements in groups of kElementLanes consecutive ones (the last
// group padded with zero matrices). Per element only the upper triangle of
// 3 x 3 node blocks is kept: for b = 0..K-1, a = 0..b, block (a, b) column-
// major, 9 K (K + 1) / 2 entries ("entry t"). Entry t of the group's lane j
// (element kElementLanes g + j) is at [(g * entries + t) * kElementLanes + j],
// so the product runs lane by lane over kElementLanes elements at once
// (vector instructions) with the memory traffic of the packed triangle.
#pragma once

namespace diffpd::internal {

constexpr int kElementLanes = 8;

// One quadrature sample of each element of a group, lane by lane (lane j:
// element j of the group), for the stiffness of an isotropic material whose
// stress differential is given by its SVD F = U diag(sigma) V^T and the
// coefficients of isotropic_differential.h. Matrices are column-major:
// entry r + 3 c of lane j at [r + 3 c][j].
struct PackedSampleLanes {
  double u[9][kElementLanes];
  double v[9][kElementLanes];
  double dp_dsigma[9][kElementLanes];  // (i, j) = dp_i / dsigma_j
  double symmetric[3][kElementLanes];  // c^sym per pair (0,1), (0,2), (1,2)
  double skew[3][kElementLanes];       // c^skew per pair
  double volume[kElementLanes];        // sample volume (m^3); 0 in lanes without an element
  // Shape-function gradients: G(a, c) = dN_a/dX_c at [a + K c] (K nodes).
  double grad[24][kElementLanes];
};

// packed_group += vol G^T dP G for each lane's sample: the sample's
// contribution to its element's Hessian (d^2 E_e / dx_e^2, upper node blocks
// in the packed layout), with dP = dP/dF assembled from the coefficients
// (AssembleIsotropicDifferential) and the product formed as
// ElasticForces' AddSampleStiffness forms it; equal to those to rounding.
// About 2400 multiply-adds per lane, all lanes in one vector instruction.
void AddPackedSampleStiffness(int nodes_per_element, const PackedSampleLanes& sample, double* packed_group);

// Entries per element matrix: 9 K (K + 1) / 2 for K nodes.
inline int PackedEntries(int nodes_per_element) { return 9 * nodes_per_element * (nodes_per_element + 1) / 2; }

// y = K z for one group: packed = the group's entries (PackedEntries(k) *
// kElementLanes doubles), z and y = 3k rows of kElementLanes lanes (row
// 3 a + i: node a, axis i; lane j: element j of the group). y is overwritten.
void ApplyPackedGroup(int nodes_per_element, const double* packed, const double (*z)[kElementLanes],
                      double (*y)[kElementLanes]);

}  // namespace diffpd::internal
