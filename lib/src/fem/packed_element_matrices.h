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

// Entries per element matrix: 9 K (K + 1) / 2 for K nodes.
inline int PackedEntries(int nodes_per_element) { return 9 * nodes_per_element * (nodes_per_element + 1) / 2; }

// y = K z for one group: packed = the group's entries (PackedEntries(k) *
// kElementLanes doubles), z and y = 3k rows of kElementLanes lanes (row
// 3 a + i: node a, axis i; lane j: element j of the group). y is overwritten.
void ApplyPackedGroup(int nodes_per_element, const double* packed, const double (*z)[kElementLanes],
                      double (*y)[kElementLanes]);

}  // namespace diffpd::internal
