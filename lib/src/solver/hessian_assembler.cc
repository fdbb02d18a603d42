#include "solver/hessian_assembler.h"

#include <algorithm>

#include "diffpd/error.h"
#include "fem/packed_element_matrices.h"

namespace diffpd::internal {
namespace {
int ValueIndex(const SparseMatrix& m, int row, int col) {
  const int* begin = m.innerIndexPtr() + m.outerIndexPtr()[col];
  const int* end = m.innerIndexPtr() + m.outerIndexPtr()[col + 1];
  const int* it = std::lower_bound(begin, end, row);
  DIFFPD_CHECK(it != end && *it == row, "entry (" << row << ", " << col << ") missing from the pattern");
  return static_cast<int>(it - m.innerIndexPtr());
}
}  // namespace

HessianAssembler::HessianAssembler(const Mesh& mesh) : k_(NodesPerElement(mesh.type)) {
  const int n = mesh.num_dofs();
  const int nb = 3 * k_;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(static_cast<size_t>(mesh.num_elements()) * nb * nb + n);
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int a = 0; a < k_; ++a)
      for (int b = 0; b < k_; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            triplets.emplace_back(3 * mesh.elements(a, e) + i, 3 * mesh.elements(b, e) + j, 0.0);
  for (int d = 0; d < n; ++d) triplets.emplace_back(d, d, 0.0);
  pattern_.resize(n, n);
  pattern_.setFromTriplets(triplets.begin(), triplets.end());
  pattern_.makeCompressed();
  block_index_.resize(static_cast<size_t>(mesh.num_elements()) * nb * nb);
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int c = 0; c < nb; ++c)
      for (int r = 0; r < nb; ++r) {
        const int row = 3 * mesh.elements(r / 3, e) + r % 3;
        const int col = 3 * mesh.elements(c / 3, e) + c % 3;
        block_index_[(static_cast<size_t>(e) * nb + c) * nb + r] = ValueIndex(pattern_, row, col);
      }
  diag_index_.resize(n);
  for (int d = 0; d < n; ++d) diag_index_[d] = ValueIndex(pattern_, d, d);
}

void HessianAssembler::FinishAssembly(const VectorXd& diagonal, const std::vector<char>& fixed, SparseMatrix* h) const {
  double* values = h->valuePtr();
  const int* rows = h->innerIndexPtr();
  for (int d = 0; d < h->rows(); ++d) values[diag_index_[d]] += diagonal(d);
  for (int col = 0; col < h->cols(); ++col)
    for (int t = h->outerIndexPtr()[col]; t < h->outerIndexPtr()[col + 1]; ++t)
      if (fixed[col] || fixed[rows[t]]) values[t] = rows[t] == col ? 1.0 : 0.0;
}

void HessianAssembler::AssemblePacked(const std::vector<double>& packed, const std::vector<double>& blocks,
                                      const VectorXd& diagonal, const std::vector<char>& fixed, SparseMatrix* h) const {
  const int entries = PackedEntries(k_), nb = 3 * k_;
  const int elements = static_cast<int>(block_index_.size() / (nb * nb));
  const int groups = (elements + kElementLanes - 1) / kElementLanes;
  DIFFPD_CHECK(packed.size() == static_cast<size_t>(groups) * entries * kElementLanes,
               "AssemblePacked: " << packed.size() << " packed entries for " << elements << " elements");
  DIFFPD_CHECK(blocks.empty() || blocks.size() == block_index_.size(), "element block count mismatch");
  *h = pattern_;
  double* values = h->valuePtr();
  for (int e = 0; e < elements; ++e) {
    const double* lane =
        packed.data() + static_cast<size_t>(e / kElementLanes) * entries * kElementLanes + e % kElementLanes;
    const int* index = block_index_.data() + static_cast<size_t>(e) * nb * nb;  // (r, c) at c nb + r
    // Packed entry t: node blocks (a, b), b = 0..K-1, a = 0..b, each 3 x 3
    // column-major; an off-diagonal block also stands for its transpose.
    int t = 0;
    for (int b = 0; b < k_; ++b)
      for (int a = 0; a <= b; ++a)
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i, ++t) {
            const double v = lane[static_cast<size_t>(t) * kElementLanes];
            const int r = 3 * a + i, c = 3 * b + j;
            values[index[c * nb + r]] += v;
            if (a != b) values[index[r * nb + c]] += v;
          }
  }
  for (size_t t = 0; t < blocks.size(); ++t) values[block_index_[t]] += blocks[t];
  FinishAssembly(diagonal, fixed, h);
}

void HessianAssembler::Assemble(const std::vector<double>& blocks, const VectorXd& diagonal,
                                const std::vector<char>& fixed, SparseMatrix* h) const {
  DIFFPD_CHECK(blocks.size() == block_index_.size(), "element block count mismatch");
  *h = pattern_;
  double* values = h->valuePtr();
  for (size_t t = 0; t < block_index_.size(); ++t) values[block_index_[t]] += blocks[t];
  FinishAssembly(diagonal, fixed, h);
}

}  // namespace diffpd::internal
