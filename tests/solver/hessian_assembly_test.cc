// Step Hessians assembled from packed element matrices equal those assembled
// from the full blocks; the direct solver of assembled Hessians analyses a
// pattern once (CHOLMOD) or at every factorisation (the paper-style LDL^T),
// solves SPD systems to rounding, and only LDL^T factorises an indefinite one.
#include <gtest/gtest.h>

#include <random>

#include "fem/elastic_forces.h"
#include "fem/fem_model.h"
#include "solver/hessian_assembler.h"
#include "solver/hessian_factorization.h"
#include "test_scenes.h"

namespace diffpd::internal {
namespace {

// Element Hessians of a deformed small beam (unprojected: indefinite blocks).
struct BeamHessians {
  Scene scene = testing::SmallBeamScene();
  FemModel fem{scene.mesh};
  ElasticForces elastic{fem, scene.energies};
  VectorXd x;
  std::vector<double> blocks;
  std::vector<char> fixed;
  VectorXd inertia;

  BeamHessians() {
    x = Eigen::Map<const VectorXd>(scene.mesh.vertices.data(), scene.mesh.num_dofs());
    for (int i = 0; i < x.size() / 3; ++i) x(3 * i + 2) += 0.4 * x(3 * i) * x(3 * i) - 0.1 * x(3 * i + 1);
    const LameField lame = LameField::Uniform(scene.material.mu(), scene.material.lambda());
    elastic.ElementHessians(x, lame, /*project_spd=*/false, &blocks, 1);
    fixed.assign(x.size(), 0);
    for (const int d : scene.dirichlet.dofs) fixed[d] = 1;
    inertia = VectorXd::Constant(x.size(), 50.0);
  }
};

TEST(HessianAssemblyTest, PackedElementMatricesAssembleToTheFullBlocksMatrix) {
  BeamHessians beam;
  const HessianAssembler assembler(beam.scene.mesh);
  std::vector<double> packed;
  beam.elastic.PackElementMatrices(beam.blocks, &packed);
  SparseMatrix full, from_packed;
  assembler.Assemble(beam.blocks, beam.inertia, beam.fixed, &full);
  assembler.AssemblePacked(packed, {}, beam.inertia, beam.fixed, &from_packed);
  ASSERT_EQ(full.nonZeros(), from_packed.nonZeros());
  EXPECT_LE((MatrixXd(full) - MatrixXd(from_packed)).norm(), 1e-13 * MatrixXd(full).norm());
  // With extra full blocks (the auxiliary energies' route): the sum.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::vector<double> extra(beam.blocks.size());
  for (double& v : extra) v = normal(rng);
  std::vector<double> sum = beam.blocks;
  for (size_t t = 0; t < sum.size(); ++t) sum[t] += extra[t];
  assembler.Assemble(sum, beam.inertia, beam.fixed, &full);
  assembler.AssemblePacked(packed, extra, beam.inertia, beam.fixed, &from_packed);
  EXPECT_LE((MatrixXd(full) - MatrixXd(from_packed)).norm(), 1e-13 * MatrixXd(full).norm());
}

// M/h^2 + K with a mass large enough to make it positive definite.
SparseMatrix SpdHessian(const BeamHessians& beam, double inertia) {
  const HessianAssembler assembler(beam.scene.mesh);
  SparseMatrix h;
  assembler.Assemble(beam.blocks, VectorXd::Constant(beam.x.size(), inertia), beam.fixed, &h);
  return h;
}

TEST(HessianAssemblyTest, CholeskyAnalysesOncePerPatternAndLdltAtEveryFactorisation) {
  const BeamHessians beam;
  const SparseMatrix h1 = SpdHessian(beam, 1e6), h2 = SpdHessian(beam, 2e6);
  const VectorXd b = VectorXd::LinSpaced(h1.rows(), -1, 1);
  for (const HessianFactorizationKind kind :
       {HessianFactorizationKind::kCholmodSupernodal, HessianFactorizationKind::kSimplicialLdlt}) {
    HessianFactorization factor(kind);
    ASSERT_TRUE(factor.Factorize(h1));
    EXPECT_GT(factor.analysis_seconds(), 0.0);
    const VectorXd z1 = factor.Solve(b);
    EXPECT_LE((h1 * z1 - b).norm(), 1e-12 * b.norm());
    ASSERT_TRUE(factor.Factorize(h2));
    const MatrixXd z2 = factor.Solve(MatrixXd(b.replicate(1, 2)));
    EXPECT_LE((h2 * z2.col(1) - b).norm(), 1e-12 * b.norm());
    EXPECT_EQ(factor.num_factorizations(), 2);
    if (kind == HessianFactorizationKind::kCholmodSupernodal) {
      EXPECT_EQ(factor.num_analyses(), 1);
      EXPECT_EQ(factor.analysis_seconds(), 0.0);
    } else {
      EXPECT_EQ(factor.num_analyses(), 2);
      EXPECT_GT(factor.analysis_seconds(), 0.0);
    }
  }
}

TEST(HessianAssemblyTest, OnlyLdltFactorisesAnIndefiniteHessian) {
  const BeamHessians beam;
  // Inertia far below the stiffness of the bent beam's compressed elements:
  // the unprojected Hessian is indefinite but (generically) nonsingular.
  SparseMatrix h = SpdHessian(beam, 0.0);
  h.diagonal().array() -= 0.5 * MatrixXd(h).diagonal().cwiseAbs().maxCoeff() * 1e-3;
  for (int d = 0; d < h.rows(); ++d)
    if (beam.fixed[d]) h.coeffRef(d, d) = 1.0;
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig{MatrixXd(h)};
  ASSERT_LT(eig.eigenvalues().minCoeff(), 0.0);
  HessianFactorization llt(HessianFactorizationKind::kCholmodSupernodal);
  EXPECT_FALSE(llt.Factorize(h));
  HessianFactorization ldlt(HessianFactorizationKind::kSimplicialLdlt);
  ASSERT_TRUE(ldlt.Factorize(h));
  const VectorXd b = VectorXd::LinSpaced(h.rows(), 1, 2);
  EXPECT_LE((h * ldlt.Solve(b) - b).norm(), 1e-9 * b.norm());
}

}  // namespace
}  // namespace diffpd::internal
