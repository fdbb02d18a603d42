// Erasing a contact active set from the prefactorised PD matrix: the Woodbury
// path, a full refactorisation and a direct reference (the matrix recovered
// from its products, factorised by Eigen) give the same solution;
// the Woodbury path never refactorises and solves once per new contact node.
#include <gtest/gtest.h>

#include <random>

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include "contact/active_set_erasure.h"
#include "fem/fem_model.h"
#include "solver/pd_system.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

VectorXd Random(int n, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

// Direct solve of A_s with the given nodes (per axis) erased, as PdSystem defines it.
VectorXd DirectReference(const internal::PdSystem& pd, const std::vector<char>& fixed, const std::vector<int>& active,
                         const VectorXd& r) {
  const int n = static_cast<int>(r.size());
  // Recover the matrix column by column from Apply (free DoFs only).
  std::vector<char> erased = fixed;
  for (const int i : active)
    for (int d = 0; d < 3; ++d) erased[3 * i + d] = 1;
  std::vector<int> free;
  for (int d = 0; d < n; ++d)
    if (!erased[d]) free.push_back(d);
  // Its nonzeros, factorised by Eigen's own sparse Cholesky (not the
  // system's CHOLMOD): a dense factorisation of the 1000-DoF plate costs
  // most of this suite's time in unoptimised and sanitized builds.
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t c = 0; c < free.size(); ++c) {
    VectorXd e = VectorXd::Zero(n);
    e(free[c]) = 1;
    const VectorXd col = pd.Apply(e);
    for (size_t r2 = 0; r2 < free.size(); ++r2)
      if (col(free[r2]) != 0) entries.emplace_back(static_cast<int>(r2), static_cast<int>(c), col(free[r2]));
  }
  const int m = static_cast<int>(free.size());
  Eigen::SparseMatrix<double> a(m, m);
  a.setFromTriplets(entries.begin(), entries.end());
  VectorXd rf(free.size());
  for (size_t k = 0; k < free.size(); ++k) rf(k) = r(free[k]);
  const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(a);
  EXPECT_EQ(llt.info(), Eigen::Success) << "the reference's matrix is not positive definite";
  const VectorXd sol = llt.solve(rf);
  VectorXd out = VectorXd::Zero(n);
  for (size_t k = 0; k < free.size(); ++k) out(free[k]) = sol(k);
  return out;
}

TEST(ActiveSetErasureTest, WoodburyRefactorisationAndDirectReferenceAgree) {
  Scene scene = testing::SmallBeamScene();
  internal::FemModel fem(scene.mesh);
  const int n = scene.mesh.num_dofs();
  // Mixed Dirichlet groups: x free at the clamp, so two factors.
  std::vector<char> fixed(n, 0);
  for (const int d : scene.dirichlet.dofs) fixed[d] = d % 3 != 0;
  internal::PdSystem wood(fem, fixed), refac(fem, fixed);
  wood.Update(0.01, 1e3, 1e5);
  refac.Update(0.01, 1e3, 1e5);
  ASSERT_EQ(wood.num_groups(), 2);
  std::mt19937_64 rng(3);
  // Active nodes at the far end and the bottom (including a clamped one: its fixed axes stay fixed).
  const std::vector<int> active = {0, 5, 12, 30, 44};
  wood.SetActiveNodes(active, ContactLinearSolve::kWoodbury);
  refac.SetActiveNodes(active, ContactLinearSolve::kRefactorize);
  MatrixXd r(n, 3);
  for (int c = 0; c < 3; ++c) r.col(c) = Random(n, &rng);
  const MatrixXd yw = wood.Solve(r), yr = refac.Solve(r);
  for (int c = 0; c < 3; ++c) {
    const VectorXd ref = DirectReference(wood, fixed, active, r.col(c));
    EXPECT_LT((yw.col(c) - ref).norm(), 1e-11 * ref.norm());
    EXPECT_LT((yr.col(c) - ref).norm(), 1e-11 * ref.norm());
    for (const int i : active) EXPECT_EQ(yw.col(c).segment<3>(3 * i).norm(), 0.0);
    // A_S y = r on the free DoFs.
    const VectorXd res = wood.Apply(yw.col(c));
    for (int d = 0; d < n; ++d) {
      if (!fixed[d] && std::find(active.begin(), active.end(), d / 3) == active.end()) {
        EXPECT_NEAR(res(d), r(d, c), 1e-9 * r.col(c).norm());
      }
    }
  }
  EXPECT_EQ(wood.num_factorizations(), 1);
  EXPECT_EQ(wood.num_active_set_factorizations(), 0);
  EXPECT_EQ(refac.num_active_set_factorizations(), 2);  // one per group
}

TEST(ActiveSetErasureTest, LargeSetsCorrectedByASecondSolveAgreeWithRefactorisation) {
  // More active nodes than kDenseCorrectionMax: the correction is applied by a
  // second solve with A instead of the product with W; both paths stay exact,
  // across growing, shrinking and repeated sets.
  const Mesh mesh = testing::BoxHexMesh(12, 12, 1, 0.12, 0.12, 0.01);
  internal::FemModel fem(mesh);
  const int n = mesh.num_dofs();
  const std::vector<char> fixed(n, 0);
  internal::PdSystem wood(fem, fixed), refac(fem, fixed);
  wood.Update(0.01, 1e3, 1e5);
  refac.Update(0.01, 1e3, 1e5);
  std::vector<int> bottom;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.vertices(2, i) < 1e-9) bottom.push_back(i);
  constexpr int kMax = internal::ActiveSetErasure::kDenseCorrectionMax;
  ASSERT_EQ(bottom.size(), 169u);
  ASSERT_GT(169, kMax);
  std::mt19937_64 rng(11);
  for (const int s : {kMax - 1, kMax + 1, 169, kMax, 169}) {
    const std::vector<int> active(bottom.begin(), bottom.begin() + s);
    wood.SetActiveNodes(active, ContactLinearSolve::kWoodbury);
    refac.SetActiveNodes(active, ContactLinearSolve::kRefactorize);
    MatrixXd r(n, 2);
    for (int c = 0; c < 2; ++c) r.col(c) = Random(n, &rng);
    const MatrixXd yw = wood.Solve(r), yr = refac.Solve(r);
    const VectorXd ref = DirectReference(wood, fixed, active, r.col(0));
    EXPECT_LT((yw.col(0) - ref).norm(), 1e-10 * ref.norm()) << s << " active nodes";
    EXPECT_LT((yw - yr).norm(), 1e-10 * yr.norm()) << s << " active nodes";
    for (const int i : active) EXPECT_EQ(yw.col(1).segment<3>(3 * i).norm(), 0.0);
  }
  EXPECT_EQ(wood.num_active_set_column_solves(), 169);  // one per node ever erased
  EXPECT_EQ(wood.num_factorizations(), 1);
}

TEST(ActiveSetErasureTest, CachedColumnsStayBoundedAsContactMovesAcrossTheSurface) {
  // A contact patch of 8 nodes sweeping over 169 bottom nodes (a rolling
  // body): the cache keeps at most 2 |S| + kCacheSlack columns, solves stay
  // exact, and a node that returns after its column was dropped is re-solved.
  const Mesh mesh = testing::BoxHexMesh(12, 12, 1, 0.12, 0.12, 0.01);
  internal::FemModel fem(mesh);
  const int n = mesh.num_dofs();
  const std::vector<char> fixed(n, 0);
  internal::PdSystem pd(fem, fixed);
  pd.Update(0.01, 1e3, 1e5);
  std::vector<int> bottom;
  for (int i = 0; i < mesh.num_vertices(); ++i)
    if (mesh.vertices(2, i) < 1e-9) bottom.push_back(i);
  constexpr int kPatch = 8;
  const int bound = 2 * kPatch + internal::ActiveSetErasure::kCacheSlack;
  std::mt19937_64 rng(3);
  for (int start = 0; start + kPatch <= static_cast<int>(bottom.size()); start += kPatch) {
    const std::vector<int> active(bottom.begin() + start, bottom.begin() + start + kPatch);
    pd.SetActiveNodes(active, ContactLinearSolve::kWoodbury);
    EXPECT_LE(pd.num_active_set_cached_columns(), bound) << "patch at " << start;
    if (start % (4 * kPatch) == 0) {
      const VectorXd r = Random(n, &rng);
      const VectorXd ref = DirectReference(pd, fixed, active, r);
      EXPECT_LT((pd.Solve(r) - ref).norm(), 1e-10 * ref.norm()) << "patch at " << start;
    }
  }
  EXPECT_EQ(pd.num_active_set_column_solves(), 168);  // 21 patches, each new
  const std::vector<int> first(bottom.begin(), bottom.begin() + kPatch);
  pd.SetActiveNodes(first, ContactLinearSolve::kWoodbury);  // dropped long ago
  EXPECT_EQ(pd.num_active_set_column_solves(), 168 + kPatch);
  const VectorXd r = Random(n, &rng);
  const VectorXd ref = DirectReference(pd, fixed, first, r);
  EXPECT_LT((pd.Solve(r) - ref).norm(), 1e-10 * ref.norm());
  EXPECT_EQ(pd.num_factorizations(), 1);
}

TEST(ActiveSetErasureTest, WoodburySolvesOnceForEachNewContactNodeAndFollowsRefactorisation) {
  Scene scene = testing::SmallBeamScene();
  internal::FemModel fem(scene.mesh);
  const int n = scene.mesh.num_dofs();
  std::vector<char> fixed(n, 0);
  for (const int d : scene.dirichlet.dofs) fixed[d] = 1;
  internal::PdSystem pd(fem, fixed);
  pd.Update(0.01, 1e3, 1e5);
  pd.SetActiveNodes({20, 21}, ContactLinearSolve::kWoodbury);
  EXPECT_EQ(pd.num_active_set_column_solves(), 2);
  pd.SetActiveNodes({20, 21, 22}, ContactLinearSolve::kWoodbury);
  EXPECT_EQ(pd.num_active_set_column_solves(), 3);
  pd.SetActiveNodes({}, ContactLinearSolve::kWoodbury);
  pd.SetActiveNodes({21, 22}, ContactLinearSolve::kWoodbury);  // cached columns
  EXPECT_EQ(pd.num_active_set_column_solves(), 3);
  // A new time step refactorises A: the erasure is rebuilt on the new factor.
  pd.Update(0.005, 1e3, 1e5);
  std::mt19937_64 rng(5);
  const VectorXd r = Random(n, &rng);
  const VectorXd ref = DirectReference(pd, fixed, {21, 22}, r);
  EXPECT_LT((pd.Solve(r) - ref).norm(), 1e-11 * ref.norm());
  EXPECT_EQ(pd.num_factorizations(), 2);
}

}  // namespace
}  // namespace diffpd
