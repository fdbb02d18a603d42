// ParallelTriangularSolve (solver/parallel_triangular_solve.h): PD's
// repeated solves with a copy of the CHOLMOD factor, in parallel over
// subtrees of the elimination tree.
//
// Properties: on one thread and on several, with 1 to 7 right-hand sides
// and from either factor layout, it solves A X = B to rounding and agrees
// with CHOLMOD's own solve; the partition leaves a minority of the factor in
// the serial top; small factors are solved serially; called inside a
// parallel region (one thread available) it still completes every subtree;
// columns that are not a lower triangular factor are refused.
#include <gtest/gtest.h>

#include <omp.h>

#include <vector>

#include "solver/cholmod_solver.h"
#include "solver/grid_matrices.h"
#include "solver/parallel_triangular_solve.h"

namespace diffpd::internal {
namespace {

// The cantilever's PD matrix pattern (33 x 9 x 9 nodes, 27-point stencil).
SparseMatrix CantileverGrid() { return HexGridMatrix(33, 9, 9, 0.5); }

TEST(ParallelTriangularSolveTest, SolvesLikeCholmodOnAnyThreadCountAndColumnCount) {
  const SparseMatrix a = CantileverGrid();
  for (const CholmodLayout layout : {CholmodLayout::kSimplicial, CholmodLayout::kSupernodal}) {
    CholmodSolver cholmod(layout, CholmodOrdering::kNestedDissection);
    ASSERT_TRUE(cholmod.Factorize(a));
    for (const int threads : {1, 2, 3}) {
      CholmodSolver copy(layout, CholmodOrdering::kNestedDissection, CholmodSolveKernel::kParallelCopy);
      copy.set_solve_threads(threads);
      ASSERT_TRUE(copy.Factorize(a));
      ASSERT_NE(copy.parallel_copy(), nullptr);
      EXPECT_EQ(copy.parallel_copy()->num_threads(), threads);
      for (const int columns : {1, 2, 3, 4, 5, 7}) {
        const MatrixXd b = MatrixXd::Random(a.rows(), columns);
        const MatrixXd x = copy.Solve(b);
        const MatrixXd reference = cholmod.Solve(b);
        EXPECT_LT((a * x - b).norm(), 1e-13 * b.norm()) << threads << " threads, " << columns << " columns";
        EXPECT_LT((x - reference).norm(), 1e-13 * reference.norm()) << threads << " threads, " << columns << " columns";
      }
      const VectorXd b = VectorXd::Random(a.rows());
      EXPECT_LT((copy.Solve(b) - cholmod.Solve(b)).norm(), 1e-13 * cholmod.Solve(b).norm());
    }
  }
}

// Nested dissection puts the largest separators at the top of the tree: the
// serial top holds some of the factor, far less than half.
TEST(ParallelTriangularSolveTest, TwoThreadPartitionLeavesAMinorityOfTheFactorSerial) {
  CholmodSolver solver(CholmodLayout::kSimplicial, CholmodOrdering::kNestedDissection,
                       CholmodSolveKernel::kParallelCopy);
  solver.set_solve_threads(2);
  ASSERT_TRUE(solver.Factorize(CantileverGrid()));
  const double serial = solver.parallel_copy()->serial_fraction();
  EXPECT_GT(serial, 0.0);
  EXPECT_LT(serial, 0.3);
}

TEST(ParallelTriangularSolveTest, SmallFactorsAreSolvedSerially) {
  CholmodSolver solver(CholmodLayout::kSimplicial, CholmodOrdering::kNestedDissection,
                       CholmodSolveKernel::kParallelCopy);
  solver.set_solve_threads(2);
  const SparseMatrix a = GridMatrix(5, 0.1);  // 125 unknowns
  ASSERT_TRUE(solver.Factorize(a));
  EXPECT_EQ(solver.parallel_copy()->num_threads(), 1);
  EXPECT_EQ(solver.parallel_copy()->serial_fraction(), 0.0);
  const MatrixXd b = MatrixXd::Random(a.rows(), 3);
  EXPECT_LT((a * solver.Solve(b) - b).norm(), 1e-13 * b.norm());
}

// Changing the thread count re-partitions the existing copy.
TEST(ParallelTriangularSolveTest, SolveThreadsTakeEffectWithoutRefactorising) {
  CholmodSolver solver(CholmodLayout::kSimplicial, CholmodOrdering::kNestedDissection,
                       CholmodSolveKernel::kParallelCopy);
  const SparseMatrix a = CantileverGrid();
  ASSERT_TRUE(solver.Factorize(a));
  EXPECT_EQ(solver.parallel_copy()->num_threads(), 1);
  solver.set_solve_threads(2);
  EXPECT_EQ(solver.parallel_copy()->num_threads(), 2);
  EXPECT_EQ(solver.num_factorizations(), 1);
  const MatrixXd b = MatrixXd::Random(a.rows(), 3);
  EXPECT_LT((a * solver.Solve(b) - b).norm(), 1e-13 * b.norm());
}

// Inside a parallel region the solve's own region gets one thread, which
// must then do every thread's subtrees.
TEST(ParallelTriangularSolveTest, CompletesInsideAParallelRegion) {
  CholmodSolver solver(CholmodLayout::kSimplicial, CholmodOrdering::kNestedDissection,
                       CholmodSolveKernel::kParallelCopy);
  solver.set_solve_threads(2);
  const SparseMatrix a = CantileverGrid();
  ASSERT_TRUE(solver.Factorize(a));
  const MatrixXd b = MatrixXd::Random(a.rows(), 3);
  const MatrixXd expected = solver.Solve(b);
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
  std::vector<double> errors(2, -1.0);
#pragma omp parallel num_threads(2)
  {
    const MatrixXd x = solver.Solve(b);
    errors[omp_get_thread_num()] = (x - expected).norm();
  }
  omp_set_max_active_levels(levels);
  for (const double e : errors) EXPECT_EQ(e, 0.0);
}

TEST(ParallelTriangularSolveTest, RefusesColumnsThatAreNotALowerFactor) {
  // 2 x 2: column 0 = {0, 1}, column 1 = {1}.
  const int rows0[] = {0, 1}, rows1[] = {1}, swapped[] = {1, 0};
  const double values0[] = {2.0, 0.5}, values1[] = {1.5}, negative[] = {-1.5};
  const int perm[] = {0, 1};
  using Column = ParallelTriangularSolve::Column;
  const auto make = [&](Column c0, Column c1) {
    return ParallelTriangularSolve::Create(
        2, perm, [&](int j) { return j == 0 ? c0 : c1; }, 1);
  };
  EXPECT_NE(make({rows0, values0, 2}, {rows1, values1, 1}), nullptr);
  EXPECT_EQ(make({swapped, values0, 2}, {rows1, values1, 1}), nullptr);  // diagonal not first
  EXPECT_EQ(make({rows0, values0, 2}, {rows1, negative, 1}), nullptr);   // non-positive pivot
  EXPECT_EQ(make({rows0, values0, 2}, {rows0, values0, 2}), nullptr);    // column 1 starts at row 0
  EXPECT_EQ(make({rows0, values0, 0}, {rows1, values1, 1}), nullptr);    // empty column
}

}  // namespace
}  // namespace diffpd::internal
