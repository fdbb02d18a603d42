#include "solver/parallel_triangular_solve.h"

#include <omp.h>

#include <algorithm>
#include <numeric>

#include "diffpd/error.h"
#include "material/simd_dispatch.h"

namespace diffpd::internal {
namespace {

// Below this many entries of L a solve is done on one thread: two parallel
// regions per solve cost more than they save (the rolling sphere's factor,
// 47.8 k entries, solves 1.25x faster on 2 threads; the cantilever's, 217 k,
// 1.2-1.7x).
constexpr double kMinParallelEntries = 40000;
// Subtrees split at most this often while searching the partition.
constexpr int kMaxSplits = 64;
// The rectangles' rows are processed kRowLanes at a time (vector lanes); each
// column is padded with zeros to a multiple of it.
constexpr int kRowLanes = 8;
inline int PaddedRows(int rows) { return (rows + kRowLanes - 1) / kRowLanes * kRowLanes; }

bool IsLowerFactor(int n, const std::function<ParallelTriangularSolve::Column(int)>& column) {
  for (int j = 0; j < n; ++j) {
    const ParallelTriangularSolve::Column c = column(j);
    if (c.count < 1 || c.rows[0] != j || !(c.values[0] > 0)) return false;
    for (int p = 1; p < c.count; ++p)
      if (c.rows[p] <= c.rows[p - 1] || c.rows[p] >= n) return false;
  }
  return true;
}

}  // namespace

std::unique_ptr<ParallelTriangularSolve> ParallelTriangularSolve::Create(int n, const int* perm,
                                                                         const std::function<Column(int)>& column,
                                                                         int num_threads) {
  DIFFPD_CHECK(n >= 0 && num_threads >= 1, "ParallelTriangularSolve: n = " << n << ", " << num_threads << " threads");
  if (!IsLowerFactor(n, column)) return nullptr;
  std::unique_ptr<ParallelTriangularSolve> s(new ParallelTriangularSolve());
  s->n_ = n;
  s->perm_.assign(perm, perm + n);

  // Supernodes: column j + 1 continues j's when it is j's first row below
  // the diagonal and its pattern is exactly j's without j.
  std::vector<int> first_col, width, node_of_col(n);
  for (int j = 0; j < n;) {
    int w = 1;
    while (j + w < n) {
      const Column prev = column(j + w - 1);
      const Column next = column(j + w);
      if (prev.count < 2 || prev.rows[1] != j + w || next.count != prev.count - 1 ||
          !std::equal(next.rows, next.rows + next.count, prev.rows + 1))
        break;
      ++w;
    }
    for (int k = 0; k < w; ++k) node_of_col[j + k] = static_cast<int>(first_col.size());
    first_col.push_back(j);
    width.push_back(w);
    j += w;
  }
  const int num_nodes = static_cast<int>(first_col.size());

  // The supernodal elimination tree (columns are in a topological order, so a
  // parent follows its children), each subtree's entries and first node
  // (subtrees are contiguous when the tree is postordered, as CHOLMOD's is;
  // checked below).
  std::vector<int> parent(num_nodes, -1), subtree_first(num_nodes);
  std::vector<double> entries(num_nodes, 0), subtree_entries(num_nodes, 0);
  std::vector<std::vector<int>> children(num_nodes);
  std::vector<int> candidates;
  double total = 0;
  for (int s = 0; s < num_nodes; ++s) {
    const Column last = column(first_col[s] + width[s] - 1);
    if (last.count > 1) parent[s] = node_of_col[last.rows[1]];
    for (int k = 0; k < width[s]; ++k) entries[s] += column(first_col[s] + k).count;
    total += entries[s];
    subtree_first[s] = s;
  }
  for (int s = 0; s < num_nodes; ++s) {
    subtree_entries[s] += entries[s];
    if (parent[s] >= 0) {
      subtree_entries[parent[s]] += subtree_entries[s];
      subtree_first[parent[s]] = std::min(subtree_first[parent[s]], subtree_first[s]);
      children[parent[s]].push_back(s);
    } else {
      candidates.push_back(s);
    }
  }
  // Each subtree must be the contiguous range [subtree_first[s], s] (a
  // postordered tree): count its nodes.
  bool postordered = true;
  std::vector<int> subtree_count(num_nodes, 1);
  for (int s = 0; s < num_nodes; ++s)
    if (parent[s] >= 0) subtree_count[parent[s]] += subtree_count[s];
  for (int s = 0; s < num_nodes; ++s)
    if (subtree_count[s] != s - subtree_first[s] + 1) postordered = false;

  // Split: assign the candidate subtrees largest first to the least loaded
  // thread; estimate the solve's time as the most loaded thread's entries
  // plus the top's; move the largest candidate's root to the top and its
  // children into the candidates, and repeat; keep the split of least
  // estimated time.
  s->num_threads_ = postordered && total >= kMinParallelEntries ? num_threads : 1;
  const int threads = s->num_threads_;
  const auto larger = [&](int a, int b) { return subtree_entries[a] > subtree_entries[b]; };
  std::vector<int> owner;
  std::vector<char> in_top(num_nodes, 0);
  if (threads > 1) {
    std::vector<char> top(num_nodes, 0);
    std::vector<int> best_candidates;
    double top_entries = 0, best_time = total + 1;
    for (int split = 0; split < kMaxSplits; ++split) {
      std::sort(candidates.begin(), candidates.end(), larger);
      std::vector<double> load(threads, 0.0);
      for (const int c : candidates) *std::min_element(load.begin(), load.end()) += subtree_entries[c];
      const double time = *std::max_element(load.begin(), load.end()) + top_entries;
      if (time < best_time) {
        best_time = time;
        best_candidates = candidates;
        in_top = top;
      }
      const int largest = candidates.front();
      if (children[largest].empty()) break;
      top[largest] = 1;
      top_entries += entries[largest];
      candidates.erase(candidates.begin());
      candidates.insert(candidates.end(), children[largest].begin(), children[largest].end());
    }
    candidates = best_candidates;
    std::vector<double> load(threads, 0.0);
    for (const int c : candidates) {
      const int t = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
      load[t] += subtree_entries[c];
      owner.push_back(t);
    }
  }

  // Blocks, node by node.
  std::vector<int> node_block(num_nodes + 1);
  for (int sn = 0; sn < num_nodes; ++sn) {
    node_block[sn] = static_cast<int>(s->blocks_.size());
    for (int k0 = 0; k0 < width[sn]; k0 += kBlockWidth) {
      Block b;
      b.col = first_col[sn] + k0;
      b.width = std::min(kBlockWidth, width[sn] - k0);
      const Column lead = column(b.col);
      b.num_rows = lead.count - b.width;
      b.num_own_rows = b.num_rows;
      b.rows_at = static_cast<long>(s->rows_.size());
      b.values_at = static_cast<long>(s->values_.size());
      b.values_by_row_at = static_cast<long>(s->values_by_row_.size());
      b.triangle_at = static_cast<long>(s->triangle_.size());
      s->rows_.insert(s->rows_.end(), lead.rows + b.width, lead.rows + lead.count);
      s->values_.resize(s->values_.size() + static_cast<size_t>(PaddedRows(b.num_rows)) * b.width, 0.0);
      s->values_by_row_.resize(s->values_by_row_.size() + static_cast<size_t>(b.num_rows) * b.width);
      s->triangle_.resize(s->triangle_.size() + static_cast<size_t>(b.width) * b.width, 0.0);
      for (int k = 0; k < b.width; ++k) {
        const Column c = column(b.col + k);  // rows: b.col + k .. b.col + width - 1, then the block's rows
        for (int q = 0; q < b.width - k; ++q) s->triangle_[b.triangle_at + k * b.width + k + q] = c.values[q];
        // The diagonal is kept as its reciprocal: the solves multiply
        // (a division per column and right-hand side is on the critical path).
        s->triangle_[b.triangle_at + k * b.width + k] = 1.0 / c.values[0];
        for (int r = 0; r < b.num_rows; ++r) {
          s->values_[b.values_at + static_cast<long>(k) * PaddedRows(b.num_rows) + r] = c.values[b.width - k + r];
          s->values_by_row_[b.values_by_row_at + static_cast<long>(r) * b.width + k] = c.values[b.width - k + r];
        }
      }
      s->blocks_.push_back(b);
    }
  }
  node_block[num_nodes] = static_cast<int>(s->blocks_.size());

  if (threads > 1) {
    s->thread_tasks_.assign(threads, {});
    for (size_t i = 0; i < candidates.size(); ++i) {
      const int root = candidates[i];
      s->thread_tasks_[owner[i]].push_back(static_cast<int>(s->tasks_.size()));
      s->tasks_.emplace_back(node_block[subtree_first[root]], node_block[root + 1]);
      const int last_col = first_col[root] + width[root] - 1;
      for (int bi = node_block[subtree_first[root]]; bi < node_block[root + 1]; ++bi) {
        Block& b = s->blocks_[bi];
        const int* rows = s->rows_.data() + b.rows_at;
        b.num_own_rows = static_cast<int>(std::upper_bound(rows, rows + b.num_rows, last_col) - rows);
      }
    }
    s->top_slot_.assign(n, -1);
    double top_entries = 0;
    for (int sn = 0; sn < num_nodes; ++sn) {
      if (!in_top[sn]) continue;
      s->top_.emplace_back(node_block[sn], node_block[sn + 1]);
      for (int k = 0; k < width[sn]; ++k) s->top_slot_[first_col[sn] + k] = s->num_top_rows_++;
      top_entries += entries[sn];
    }
    s->serial_fraction_ = top_entries / total;
    // Every row a subtree's block sends to a buffer must be a top column
    // (true for an elimination tree; checked, since a wrong slot would
    // write outside the buffers).
    for (const Range& task : s->tasks_)
      for (int bi = task.first; bi < task.second; ++bi) {
        const Block& b = s->blocks_[bi];
        for (int r = b.num_own_rows; r < b.num_rows; ++r)
          DIFFPD_CHECK(s->top_slot_[s->rows_[b.rows_at + r]] >= 0,
                       "ParallelTriangularSolve: row " << s->rows_[b.rows_at + r] << " of column " << b.col
                                                       << " is neither in its subtree nor in the top");
      }
  }
  return s;
}

namespace {

// kRowLanes doubles as one value (GCC/Clang vector extension): each clone
// (simd_dispatch.h) maps it to its widest registers; the baseline splits it.
typedef double RowLanes __attribute__((vector_size(8 * kRowLanes)));
typedef double RowLanesUnaligned __attribute__((vector_size(8 * kRowLanes), aligned(8)));

// (Through a pointer: returning the type by value would warn that its ABI
// differs between the clones.)
DIFFPD_SIMD_INLINE void LoadRowLanes(const double* p, RowLanes* out) {
  *out = *reinterpret_cast<const RowLanesUnaligned*>(p);
}

// One block of W columns for K right-hand sides, y row-interleaved (row i at
// y[K i]). The rectangle is column-major with each column padded with zeros
// to a multiple of kRowLanes rows (PaddedRows), so both products run on
// groups of kRowLanes rows as vector operations.
// Forward: solves the triangle for the block's rows of y, then subtracts the
// rectangle times them, rows [0, own) from y and [own, num_rows) from
// top_buffer at top_slot[row].
template <int K, int W>
DIFFPD_SIMD_INLINE void ForwardBlock(const double* tri, const int* rows, const double* values, int num_rows, int own,
                                     double* y, double* yc, double* top_buffer, const int* top_slot) {
  double v[W][K];
  for (int k = 0; k < W; ++k)
    for (int d = 0; d < K; ++d) v[k][d] = yc[K * k + d];
  for (int k = 0; k < W; ++k) {
    const double inv = tri[k * W + k];  // 1 / L(k, k)
    for (int d = 0; d < K; ++d) v[k][d] *= inv;
    for (int k2 = k + 1; k2 < W; ++k2)
      for (int d = 0; d < K; ++d) v[k2][d] -= tri[k * W + k2] * v[k][d];
  }
  for (int k = 0; k < W; ++k)
    for (int d = 0; d < K; ++d) yc[K * k + d] = v[k][d];
  const int ld = PaddedRows(num_rows);
  for (int r0 = 0; r0 < num_rows; r0 += kRowLanes) {
    RowLanes acc[K] = {};
    for (int k = 0; k < W; ++k) {
      RowLanes l;
      LoadRowLanes(values + static_cast<long>(k) * ld + r0, &l);
      for (int d = 0; d < K; ++d) acc[d] += l * v[k][d];
    }
    const int count = std::min(kRowLanes, num_rows - r0);
    for (int i = 0; i < count; ++i) {
      const int r = r0 + i, row = rows[r];
      double* dst = r < own ? y + static_cast<long>(K) * row : top_buffer + static_cast<long>(K) * top_slot[row];
      for (int d = 0; d < K; ++d) dst[d] -= acc[d][i];
    }
  }
}

// Backward: subtracts the rectangle (transposed) times x, then solves the
// transposed triangle. Reads the row-major copy of the rectangle: a full-width
// row (W = kRowLanes) is one vector, so each row costs K vector
// multiply-adds with no sums across lanes.
template <int K, int W>
DIFFPD_SIMD_INLINE void BackwardBlock(const double* tri, const int* rows, const double* values_by_row, int num_rows,
                                      const double* y, double* yc) {
  // Two sets of accumulators (even and odd rows): each sum is a chain of
  // dependent multiply-adds, so two chains per entry halve the latency bound.
  double a[W][K] = {};
  if constexpr (W == kRowLanes) {
    RowLanes even[K] = {}, odd[K] = {};  // [d][k]
    int r = 0;
    for (; r + 1 < num_rows; r += 2) {
      RowLanes l0;
      LoadRowLanes(values_by_row + static_cast<long>(r) * W, &l0);
      RowLanes l1;
      LoadRowLanes(values_by_row + static_cast<long>(r + 1) * W, &l1);
      const double* x0 = y + static_cast<long>(K) * rows[r];
      const double* x1 = y + static_cast<long>(K) * rows[r + 1];
      for (int d = 0; d < K; ++d) {
        even[d] += l0 * x0[d];
        odd[d] += l1 * x1[d];
      }
    }
    if (r < num_rows) {
      RowLanes l0;
      LoadRowLanes(values_by_row + static_cast<long>(r) * W, &l0);
      const double* x0 = y + static_cast<long>(K) * rows[r];
      for (int d = 0; d < K; ++d) even[d] += l0 * x0[d];
    }
    for (int d = 0; d < K; ++d) even[d] += odd[d];
    for (int k = 0; k < W; ++k)
      for (int d = 0; d < K; ++d) a[k][d] = even[d][k];
  } else {
    double odd[W][K] = {};
    int r = 0;
    for (; r + 1 < num_rows; r += 2) {
      const double* l0 = values_by_row + static_cast<long>(r) * W;
      const double* x0 = y + static_cast<long>(K) * rows[r];
      const double* x1 = y + static_cast<long>(K) * rows[r + 1];
      for (int k = 0; k < W; ++k)
        for (int d = 0; d < K; ++d) {
          a[k][d] += l0[k] * x0[d];
          odd[k][d] += l0[W + k] * x1[d];
        }
    }
    if (r < num_rows) {
      const double* l0 = values_by_row + static_cast<long>(r) * W;
      const double* x0 = y + static_cast<long>(K) * rows[r];
      for (int k = 0; k < W; ++k)
        for (int d = 0; d < K; ++d) a[k][d] += l0[k] * x0[d];
    }
    for (int k = 0; k < W; ++k)
      for (int d = 0; d < K; ++d) a[k][d] += odd[k][d];
  }
  for (int k = W - 1; k >= 0; --k) {
    for (int d = 0; d < K; ++d) {
      double t = yc[K * k + d] - a[k][d];
      for (int k2 = k + 1; k2 < W; ++k2) t -= tri[k * W + k2] * yc[K * k2 + d];
      yc[K * k + d] = t * tri[k * W + k];  // tri's diagonal holds 1 / L(k, k)
    }
  }
}

// The kernels for a block of width w (1..kBlockWidth), compile-time widths:
// a switch, not a lambda, so that everything stays inlined in the caller's
// clone (simd_dispatch.h).
static_assert(ParallelTriangularSolve::kBlockWidth == 8, "the switches cover widths 1..8");
#define DIFFPD_WIDTH_CASES(CALL) \
  switch (w) {                   \
    case 1:                      \
      CALL(1);                   \
      break;                     \
    case 2:                      \
      CALL(2);                   \
      break;                     \
    case 3:                      \
      CALL(3);                   \
      break;                     \
    case 4:                      \
      CALL(4);                   \
      break;                     \
    case 5:                      \
      CALL(5);                   \
      break;                     \
    case 6:                      \
      CALL(6);                   \
      break;                     \
    case 7:                      \
      CALL(7);                   \
      break;                     \
    default:                     \
      CALL(8);                   \
      break;                     \
  }

template <int K>
DIFFPD_SIMD_INLINE void ForwardBlockK(const double* tri, int w, const int* rows, const double* values, int num_rows,
                                      int own, double* y, double* yc, double* top_buffer, const int* top_slot) {
#define DIFFPD_FORWARD(W) ForwardBlock<K, W>(tri, rows, values, num_rows, own, y, yc, top_buffer, top_slot)
  DIFFPD_WIDTH_CASES(DIFFPD_FORWARD)
#undef DIFFPD_FORWARD
}

template <int K>
DIFFPD_SIMD_INLINE void BackwardBlockK(const double* tri, int w, const int* rows, const double* values, int num_rows,
                                       const double* y, double* yc) {
#define DIFFPD_BACKWARD(W) BackwardBlock<K, W>(tri, rows, values, num_rows, y, yc)
  DIFFPD_WIDTH_CASES(DIFFPD_BACKWARD)
#undef DIFFPD_BACKWARD
}
#undef DIFFPD_WIDTH_CASES

// The arrays the block kernels read (not owned).
struct FactorArrays {
  const ParallelTriangularSolve::Block* blocks;
  const double* triangle;
  const int* rows;
  const double* values;         // column-major rectangles
  const double* values_by_row;  // row-major rectangles
  const int* top_slot;
};

template <int K>
DIFFPD_SIMD_INLINE void ForwardBlocksK(const FactorArrays& f, int first, int last, double* y, double* top_buffer) {
  for (int bi = first; bi < last; ++bi) {
    const ParallelTriangularSolve::Block& b = f.blocks[bi];
    ForwardBlockK<K>(f.triangle + b.triangle_at, b.width, f.rows + b.rows_at, f.values + b.values_at, b.num_rows,
                     top_buffer ? b.num_own_rows : b.num_rows, y, y + static_cast<long>(K) * b.col, top_buffer,
                     f.top_slot);
  }
}

template <int K>
DIFFPD_SIMD_INLINE void BackwardBlocksK(const FactorArrays& f, int first, int last, double* y) {
  for (int bi = last - 1; bi >= first; --bi) {
    const ParallelTriangularSolve::Block& b = f.blocks[bi];
    BackwardBlockK<K>(f.triangle + b.triangle_at, b.width, f.rows + b.rows_at, f.values_by_row + b.values_by_row_at,
                      b.num_rows, y, y + static_cast<long>(K) * b.col);
  }
}

// Forward substitution over blocks [first, last) in ascending order, and the
// backward over them in descending order, for K = 1..4 right-hand sides; one
// clone per vector width (simd_dispatch.h), called per range of blocks.
DIFFPD_SIMD_CLONES
void ForwardBlocks(int k_rhs, const FactorArrays& f, int first, int last, double* y, double* top_buffer) {
  switch (k_rhs) {
    case 1:
      ForwardBlocksK<1>(f, first, last, y, top_buffer);
      break;
    case 2:
      ForwardBlocksK<2>(f, first, last, y, top_buffer);
      break;
    case 3:
      ForwardBlocksK<3>(f, first, last, y, top_buffer);
      break;
    default:
      ForwardBlocksK<4>(f, first, last, y, top_buffer);
      break;
  }
}

DIFFPD_SIMD_CLONES
void BackwardBlocks(int k_rhs, const FactorArrays& f, int first, int last, double* y) {
  switch (k_rhs) {
    case 1:
      BackwardBlocksK<1>(f, first, last, y);
      break;
    case 2:
      BackwardBlocksK<2>(f, first, last, y);
      break;
    case 3:
      BackwardBlocksK<3>(f, first, last, y);
      break;
    default:
      BackwardBlocksK<4>(f, first, last, y);
      break;
  }
}

}  // namespace

template <int K>
void ParallelTriangularSolve::SolveColumns(const double* b, double* x) const {
  static_assert(K >= 1 && K <= 4, "1 to 4 right-hand sides per solve");
  const FactorArrays f{blocks_.data(), triangle_.data(),      rows_.data(),
                       values_.data(), values_by_row_.data(), top_slot_.data()};
  const int n = n_;
  std::vector<double> y(static_cast<size_t>(K) * n);
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < K; ++d) y[K * i + d] = b[perm_[i] + static_cast<long>(d) * n];
  const int num_blocks = static_cast<int>(blocks_.size());
  if (num_threads_ == 1) {
    ForwardBlocks(K, f, 0, num_blocks, y.data(), nullptr);
    BackwardBlocks(K, f, 0, num_blocks, y.data());
  } else {
    const int threads = num_threads_;
    std::vector<double> buffers(static_cast<size_t>(threads) * K * num_top_rows_, 0.0);
    const long buffer_size = static_cast<long>(K) * num_top_rows_;
    // A thread given fewer threads than asked (a nested region) takes over
    // the missing threads' tasks; buffers stay per task list.
#pragma omp parallel num_threads(threads)
    {
      for (int t = omp_get_thread_num(); t < threads; t += omp_get_num_threads())
        for (const int task : thread_tasks_[t])
          ForwardBlocks(K, f, tasks_[task].first, tasks_[task].second, y.data(), buffers.data() + t * buffer_size);
    }
    for (const Range& range : top_) {
      for (int bi = range.first; bi < range.second; ++bi) {
        const Block& block = blocks_[bi];
        for (int k = 0; k < block.width; ++k) {
          const long slot = static_cast<long>(K) * top_slot_[block.col + k];
          for (int t = 0; t < threads; ++t)
            for (int d = 0; d < K; ++d) y[K * (block.col + k) + d] += buffers[t * buffer_size + slot + d];
        }
        ForwardBlocks(K, f, bi, bi + 1, y.data(), nullptr);
      }
    }
    for (auto range = top_.rbegin(); range != top_.rend(); ++range)
      BackwardBlocks(K, f, range->first, range->second, y.data());
#pragma omp parallel num_threads(threads)
    {
      for (int t = omp_get_thread_num(); t < threads; t += omp_get_num_threads())
        for (const int task : thread_tasks_[t]) BackwardBlocks(K, f, tasks_[task].first, tasks_[task].second, y.data());
    }
  }
  for (int i = 0; i < n; ++i)
    for (int d = 0; d < K; ++d) x[perm_[i] + static_cast<long>(d) * n] = y[K * i + d];
}

std::size_t ParallelTriangularSolve::bytes() const {
  std::size_t tasks = 0;
  for (const std::vector<int>& t : thread_tasks_) tasks += t.capacity() * sizeof(int);
  return perm_.capacity() * sizeof(int) + blocks_.capacity() * sizeof(Block) + rows_.capacity() * sizeof(int) +
         (values_.capacity() + values_by_row_.capacity() + triangle_.capacity()) * sizeof(double) +
         (tasks_.capacity() + top_.capacity()) * sizeof(Range) + tasks + top_slot_.capacity() * sizeof(int);
}

void ParallelTriangularSolve::Solve(const double* b, double* x, int m) const {
  const long n = n_;
  for (int c = 0; c < m;) {
    const int left = m - c;
    const long at = c * n;
    if (left >= 4) {
      SolveColumns<4>(b + at, x + at);
      c += 4;
    } else if (left == 3) {
      SolveColumns<3>(b + at, x + at);
      c += 3;
    } else if (left == 2) {
      SolveColumns<2>(b + at, x + at);
      c += 2;
    } else {
      SolveColumns<1>(b + at, x + at);
      c += 1;
    }
  }
}

}  // namespace diffpd::internal
