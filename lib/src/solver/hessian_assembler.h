// Assembly of 3n x 3n sparse Hessians from element blocks (internal). The
// pattern (3x3 blocks of node pairs sharing an element) is built once; each
// assembly only writes values, so CHOLMOD's symbolic analysis is reused.
#pragma once

#include <vector>

#include "diffpd/mesh.h"
#include "diffpd/types.h"

namespace diffpd::internal {

class HessianAssembler {
 public:
  explicit HessianAssembler(const Mesh& mesh);

  // *h = diag(diagonal) + sum_e K_e, with every row and column of a fixed DoF
  // replaced by the identity's. `blocks` holds the (3K)^2 column-major element
  // matrices (local DoF 3a + i) one after another; `fixed` has 3n flags.
  void Assemble(const std::vector<double>& blocks, const VectorXd& diagonal, const std::vector<char>& fixed,
                SparseMatrix* h) const;
  // The same with the element matrices given packed (upper node blocks,
  // interleaved: ElasticForces::PackedElementHessians, fem/
  // packed_element_matrices.h) plus `blocks` in Assemble's layout, or none
  // when `blocks` is empty (the auxiliary energies' Hessians); equal to
  // Assemble of the unpacked sum.
  void AssemblePacked(const std::vector<double>& packed, const std::vector<double>& blocks, const VectorXd& diagonal,
                      const std::vector<char>& fixed, SparseMatrix* h) const;

 private:
  int k_ = 0;
  SparseMatrix pattern_;
  std::vector<int> block_index_;  // per element, (3K)^2 value indices
  std::vector<int> diag_index_;   // per DoF
  void FinishAssembly(const VectorXd& diagonal, const std::vector<char>& fixed, SparseMatrix* h) const;
};

}  // namespace diffpd::internal
