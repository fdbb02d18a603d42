// Repeated solves with one sparse Cholesky factor, in parallel over subtrees
// of its elimination tree (internal).
//
// P A P^T = L L^T is copied once, after a factorisation, into blocks of at
// most kBlockWidth consecutive columns of one supernode (columns whose
// patterns below the diagonal agree): per block a dense lower triangle and
// the rows below it, each row's block entries contiguous. A forward or
// backward pass then loads and stores each right-hand-side row once per
// block instead of once per column, in fixed-size loops over the block's
// columns and the right-hand sides.
//
// The elimination tree is split into disjoint subtrees, given to threads by
// their entries (largest first, to the least loaded thread), and a serial
// top: the supernodes above them (with nested dissection, the largest
// separators). Forward, each thread eliminates its subtrees, its updates of
// the top's rows going to a buffer of its own; then the top. Backward, the
// top, then the subtrees in parallel (they only read the top). Each entry of
// L is used exactly as in a serial solve; only the order of the sums
// differs, so results agree with CHOLMOD's solve to rounding.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

namespace diffpd::internal {

class ParallelTriangularSolve {
 public:
  // Column j of L: `count` entries, `rows` strictly ascending starting with
  // the diagonal j; `values` alongside. Pointers need only live during Create.
  struct Column {
    const int* rows;
    const double* values;
    int count;
  };

  // Copies the n x n factor given column by column; `perm` (n entries): row k
  // of P A P^T is row perm[k] of A (CHOLMOD's Perm). Partitions for
  // `num_threads` (>= 1; small factors are solved serially). Returns nullptr
  // if the columns are not a lower triangular factor as described (the
  // caller then keeps its own solve).
  static std::unique_ptr<ParallelTriangularSolve> Create(int n, const int* perm,
                                                         const std::function<Column(int)>& column, int num_threads);

  // X = A^-1 B for m right-hand sides: b and x are n x m, column-major, and
  // must not overlap.
  void Solve(const double* b, double* x, int m) const;

  int num_threads() const { return num_threads_; }
  // Bytes held by the copy (values, row indices, triangles, partition).
  std::size_t bytes() const;
  // An upper estimate of the bytes a copy of an n x n factor with
  // `factor_nonzeros` entries takes, for the memory check before the copy is
  // made: two layouts of the values and the row indices (a tenth more for
  // the padding of the blocks' rows), and per column at most a block
  // triangle's row (kBlockWidth doubles), 7 padding rows and the partition.
  static double EstimatedBytes(int n, double factor_nonzeros) {
    return 1.1 * factor_nonzeros * (2 * sizeof(double) + sizeof(int)) + 160.0 * n;
  }
  // Share of L's entries in the serial top (0 when solved serially: all of
  // it runs on one thread, none of it waits).
  double serial_fraction() const { return serial_fraction_; }

  // Columns per block: 8 measured faster than 4 on the PD matrices of the
  // cantilever (1x-4x).
  static constexpr int kBlockWidth = 8;

  // Up to kBlockWidth consecutive columns of one supernode: their triangle
  // and the rectangle of rows below it (layout: the solve kernels').
  struct Block {
    int col;                // first column
    int width;              // columns, <= kBlockWidth
    int num_rows;           // rows below the triangle, ascending
    int num_own_rows;       // in a subtree task: the leading rows inside its subtree
    long rows_at;           // into rows_
    long values_at;         // into values_: num_rows x width, column-major, columns zero-padded to a multiple of 8 rows
    long values_by_row_at;  // into values_by_row_: the same entries num_rows x width, row-major
    long triangle_at;       // into triangle_: width x width, column-major, 1 / L(k, k) on the diagonal
  };

 private:
  using Range = std::pair<int, int>;  // blocks [first, second)

  ParallelTriangularSolve() = default;
  template <int K>
  void SolveColumns(const double* b, double* x) const;

  int n_ = 0;
  int num_threads_ = 1;
  double serial_fraction_ = 0;
  std::vector<int> perm_;
  std::vector<Block> blocks_;
  std::vector<int> rows_;
  // The rectangles below the blocks' triangles twice: column-major for the
  // forward substitution (vector operations over rows, no sums across
  // lanes), row-major for the backward (a full-width row is one vector).
  // Measured on the rolling sphere's factor (823 columns, 47.8 k entries;
  // 3 right-hand sides, 1 thread, minimum of 15 x 400 solves, alternating
  // builds): 82-86 us per solve with one row-major copy and scalar kernels,
  // 58-83 us with the column-major copy alone, 52-68 us with both (the cost:
  // one more copy of L's off-diagonal entries).
  std::vector<double> values_;
  std::vector<double> values_by_row_;
  std::vector<double> triangle_;
  // Parallel partition (num_threads_ > 1): subtree tasks per thread, the
  // top's block ranges in ascending order, and each row's slot in a thread's
  // top buffer (-1 below the top).
  std::vector<Range> tasks_;
  std::vector<std::vector<int>> thread_tasks_;
  std::vector<Range> top_;
  std::vector<int> top_slot_;
  int num_top_rows_ = 0;
};

}  // namespace diffpd::internal
