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

#include <vector>

#include "solver/cholmod_solver.h"

namespace diffpd::internal {
namespace {

// The 3D grid Laplacian (n^3 unknowns) plus shift * I: SPD for shift > 0.
SparseMatrix GridMatrix(int n, double shift) {
  const int size = n * n * n;
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j, int k) { return (i * n + j) * n + k; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const int r = id(i, j, k);
        t.emplace_back(r, r, 6.0 + shift);
        if (i + 1 < n) t.emplace_back(r, id(i + 1, j, k), -1.0), t.emplace_back(id(i + 1, j, k), r, -1.0);
        if (j + 1 < n) t.emplace_back(r, id(i, j + 1, k), -1.0), t.emplace_back(id(i, j + 1, k), r, -1.0);
        if (k + 1 < n) t.emplace_back(r, id(i, j, k + 1), -1.0), t.emplace_back(id(i, j, k + 1), r, -1.0);
      }
  SparseMatrix a(size, size);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

// A 27-point stencil on an nx x ny x nz node grid (a hexahedral mesh's
// Laplacian pattern, as in the PD matrix) plus shift * I.
SparseMatrix HexGridMatrix(int nx, int ny, int nz, double shift) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [&](int i, int j, int k) { return (i * ny + j) * nz + k; };
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (int di = -1; di <= 1; ++di)
          for (int dj = -1; dj <= 1; ++dj)
            for (int dk = -1; dk <= 1; ++dk) {
              const int a = i + di, b = j + dj, c = k + dk;
              if (a < 0 || b < 0 || c < 0 || a >= nx || b >= ny || c >= nz) continue;
              const bool diagonal = di == 0 && dj == 0 && dk == 0;
              t.emplace_back(id(i, j, k), id(a, b, c), diagonal ? 26.0 + shift : -1.0);
            }
  SparseMatrix m(nx * ny * nz, nx * ny * nz);
  m.setFromTriplets(t.begin(), t.end());
  return m;
}

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
