// CholmodSolver (solver/cholmod_solver.h): the sparse Cholesky behind Newton
// and PD.
//
// Properties: both layouts solve SPD systems (several right-hand sides) to
// rounding; a matrix that is not positive definite is reported, not solved;
// the pattern is analysed once per sparsity pattern; and a factorisation,
// which runs CHOLMOD's OpenMP loops on the calling thread, leaves the
// caller's OpenMP settings as they were; nested dissection fills less than
// CHOLMOD's automatic choice on a hexahedral mesh's PD matrix.
#include <gtest/gtest.h>

#include <omp.h>

#include "solver/cholmod_solver.h"
#include "solver/grid_matrices.h"

namespace diffpd::internal {
namespace {

TEST(CholmodSolverTest, NestedDissectionFillsLessThanTheAutomaticOrderingOnAHexMesh) {
  // The cantilever's node grid (33 x 9 x 9, 2 673 nodes).
  const SparseMatrix a = HexGridMatrix(33, 9, 9, 0.5);
  for (CholmodLayout layout : {CholmodLayout::kSimplicial, CholmodLayout::kSupernodal}) {
    CholmodSolver automatic(layout), nested(layout, CholmodOrdering::kNestedDissection);
    ASSERT_TRUE(automatic.Factorize(a));
    ASSERT_TRUE(nested.Factorize(a));
    EXPECT_LT(nested.factor_nonzeros(), 0.85 * automatic.factor_nonzeros());
    const MatrixXd b = MatrixXd::Random(a.rows(), 3);
    EXPECT_LT((a * nested.Solve(b) - b).norm(), 1e-12 * b.norm());
    EXPECT_LT((nested.Solve(b) - automatic.Solve(b)).norm(), 1e-12 * automatic.Solve(b).norm());
  }
}

TEST(CholmodSolverTest, BothLayoutsSolveSeveralRightHandSides) {
  const SparseMatrix a = GridMatrix(12, 0.1);
  const MatrixXd b = MatrixXd::Random(a.rows(), 3);
  for (const CholmodLayout layout : {CholmodLayout::kSupernodal, CholmodLayout::kSimplicial}) {
    CholmodSolver solver(layout);
    ASSERT_TRUE(solver.Factorize(a));
    const MatrixXd x = solver.Solve(b);
    EXPECT_LE((a * x - b).norm(), 1e-12 * b.norm());
    const VectorXd x0 = solver.Solve(VectorXd(b.col(0)));
    EXPECT_LE((x0 - x.col(0)).norm(), 1e-14 * x.col(0).norm());
  }
}

TEST(CholmodSolverTest, ReportsAMatrixThatIsNotPositiveDefinite) {
  CholmodSolver solver;
  EXPECT_FALSE(solver.Factorize(GridMatrix(6, -7.0)));  // eigenvalues down to -7 + O(h^2) < 0
  EXPECT_FALSE(solver.factorized());
}

TEST(CholmodSolverTest, AnalysesEachPatternOnce) {
  CholmodSolver solver;
  ASSERT_TRUE(solver.Factorize(GridMatrix(8, 0.1)));
  ASSERT_TRUE(solver.Factorize(GridMatrix(8, 0.5)));  // same pattern, new values
  EXPECT_EQ(solver.num_analyses(), 1);
  ASSERT_TRUE(solver.Factorize(GridMatrix(9, 0.1)));  // new pattern
  EXPECT_EQ(solver.num_analyses(), 2);
  EXPECT_EQ(solver.num_factorizations(), 3);
}

// The factorisation serialises OpenMP only for its own duration: afterwards
// the caller's limit on active levels is back and a 2-thread region gets its
// 2 threads.
TEST(CholmodSolverTest, FactorizationLeavesTheCallersOpenMpSettingsUnchanged) {
  const int levels = omp_get_max_active_levels();
  CholmodSolver solver;
  ASSERT_TRUE(solver.Factorize(GridMatrix(16, 0.1)));
  EXPECT_EQ(omp_get_max_active_levels(), levels);
  int team = 0;
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    team = omp_get_num_threads();
  }
  EXPECT_EQ(team, 2);
}

}  // namespace
}  // namespace diffpd::internal
