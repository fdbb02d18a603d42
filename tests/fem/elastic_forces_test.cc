// ElasticForces (fem/elastic_forces.h): the element loop that evaluates the
// elastic energy, its gradient and the Lame adjoints, with the quadrature
// points' SVDs and volume projections computed in batches (8 points of a
// hexahedron, or the single points of 8 consecutive tetrahedra).
//
// Properties: the energy is the quadrature sum of the reference densities
// (diffpd::EnergyDensity), the gradient matches central differences of the
// energy, the result does not depend on the warm-start caches or the thread
// count, the per-part Lame adjoints are z . grad E at unit parameters, and the
// element Hessians are the gradient's derivative, symmetric, and give the
// same products as the per-sample stress differentials.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "diffpd/material.h"
#include "fem/elastic_forces.h"
#include "fem/fem_model.h"
#include "material/density_kernels.h"
#include "test_scenes.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

using internal::ElasticForces;
using internal::FemModel;
using internal::LameField;

// Rest positions moved by a smooth bend and twist plus per-node noise of
// `noise` m (the beams are 4 cm thick), so that samples see distinct,
// moderately large deformations (and, with large noise, some inversions).
VectorXd DeformedPositions(const Mesh& mesh, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  VectorXd x(mesh.num_dofs());
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Vec3 p = mesh.vertices.col(v);
    const double a = 3.0 * p(0);
    x.segment<3>(3 * v) = Vec3(p(0) * 1.05, std::cos(a) * p(1) - std::sin(a) * p(2) + 0.5 * p(0) * p(0),
                               std::sin(a) * p(1) + std::cos(a) * p(2));
    for (int d = 0; d < 3; ++d) x(3 * v + d) += noise * normal(rng);
  }
  return x;
}

// sum_s vol_s sum_energies Psi(F_s) with the public reference densities.
double ReferenceEnergy(const FemModel& fem, const std::vector<ElasticEnergy>& energies, const VectorXd& x, double mu,
                       double lambda) {
  const MaterialParameters m = [&] {
    // E and nu with the given Lame parameters.
    MaterialParameters p;
    p.poissons_ratio = lambda / (2 * (lambda + mu));
    p.youngs_modulus = 2 * mu * (1 + p.poissons_ratio);
    return p;
  }();
  double total = 0;
  const int k = fem.nodes_per_element(), q_per = fem.samples_per_element();
  for (int e = 0; e < fem.num_elements(); ++e) {
    for (int q = 0; q < q_per; ++q) {
      const int s = e * q_per + q;
      Mat3 F = Mat3::Zero();
      for (int a = 0; a < k; ++a)
        for (int j = 0; j < 3; ++j) F.col(j) += x.segment<3>(3 * fem.mesh().elements(a, e)) * fem.grad(s)[a + k * j];
      for (const ElasticEnergy energy : energies)
        total += fem.sample_volume(s) * EnergyDensity(energy, F, m.mu(), m.lambda());
    }
  }
  return total;
}

struct Case {
  bool tets;
  std::vector<ElasticEnergy> energies;
  double noise;
};

// A case's beam with its FEM model and elastic forces (not copyable: fem
// refers to scene.mesh, forces to fem).
struct CaseBody {
  Scene scene;
  FemModel fem;
  ElasticForces forces;
  explicit CaseBody(const Case& c) : scene(testing::SmallBeamScene(c.tets)), fem(scene.mesh), forces(fem, c.energies) {}
};

// n entries drawn from N(0, 1) with *rng.
VectorXd NormalVector(int n, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  VectorXd v(n);
  for (int i = 0; i < n; ++i) v(i) = normal(*rng);
  return v;
}

std::vector<Case> Cases() {
  const std::vector<ElasticEnergy> pd = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  return {{false, pd, 1e-3},
          {true, pd, 1e-3},
          {false, pd, 1.5e-2},
          {true, pd, 1.5e-2},
          {false, {ElasticEnergy::kCorotated}, 1e-3},
          {true, {ElasticEnergy::kNeoHookean}, 1e-3}};
}

TEST(ElasticForcesTest, EnergyIsTheQuadratureSumOfTheReferenceDensities) {
  const double mu = 7e4, lambda = 2.8e5;
  for (const Case& c : Cases()) {
    CaseBody body(c);
    const VectorXd x = DeformedPositions(body.scene.mesh, c.noise, 3);
    const double expected = ReferenceEnergy(body.fem, c.energies, x, mu, lambda);
    const double energy = body.forces.EnergyAndGradient(x, LameField::Uniform(mu, lambda), nullptr, 1);
    EXPECT_NEAR(energy, expected, 1e-12 * std::abs(expected)) << "tets " << c.tets << " noise " << c.noise;
  }
}

TEST(ElasticForcesTest, GradientMatchesCentralDifferencesOfTheEnergy) {
  const double mu = 7e4, lambda = 2.8e5;
  for (const Case& c : Cases()) {
    CaseBody body(c);
    ElasticForces& forces = body.forces;
    const VectorXd x = DeformedPositions(body.scene.mesh, c.noise, 4);
    VectorXd grad;
    forces.EnergyAndGradient(x, LameField::Uniform(mu, lambda), &grad, 1);
    const auto energy = [&](const VectorXd& y) {
      return forces.EnergyAndGradient(y, LameField::Uniform(mu, lambda), nullptr, 1);
    };
    std::mt19937 rng(5);
    for (int trial = 0; trial < 3; ++trial) {
      const VectorXd dir = NormalVector(static_cast<int>(x.size()), &rng);
      EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(energy, x, dir, grad.dot(dir))))
          << "tets " << c.tets << " noise " << c.noise;
    }
  }
}

// The SVDs are warm-started from the previous evaluation's V per sample;
// the result must not depend on that history, nor on the thread count.
TEST(ElasticForcesTest, ResultDoesNotDependOnWarmStartsOrThreads) {
  const double mu = 7e4, lambda = 2.8e5;
  for (const bool tets : {false, true}) {
    const Scene scene = testing::SmallBeamScene(tets);
    FemModel fem(scene.mesh);
    ElasticForces warm(fem, scene.energies);
    const VectorXd x = DeformedPositions(scene.mesh, 1e-3, 6);
    VectorXd g_warm, g_cold, g_threads;
    // History: a different state, then x.
    warm.EnergyAndGradient(DeformedPositions(scene.mesh, 1e-2, 7), LameField::Uniform(mu, lambda), nullptr, 1);
    const double e_warm = warm.EnergyAndGradient(x, LameField::Uniform(mu, lambda), &g_warm, 1);
    ElasticForces cold(fem, scene.energies);
    const double e_cold = cold.EnergyAndGradient(x, LameField::Uniform(mu, lambda), &g_cold, 1);
    const double e_threads = cold.EnergyAndGradient(x, LameField::Uniform(mu, lambda), &g_threads, 2);
    EXPECT_NEAR(e_warm, e_cold, 1e-13 * e_cold);
    EXPECT_LE((g_warm - g_cold).norm(), 1e-12 * g_cold.norm());
    EXPECT_NEAR(e_threads, e_cold, 1e-13 * e_cold);
    EXPECT_LE((g_threads - g_cold).norm(), 1e-12 * g_cold.norm());
  }
}

// PartLameDots(x, z) = per part, z . grad E restricted to the part's
// elements at (mu, lambda) = (1, 0) and (0, 1).
TEST(ElasticForcesTest, PartLameDotsAreTheUnitParameterGradientsAlongZ) {
  for (const bool tets : {false, true}) {
    const Scene scene = testing::SmallBeamScene(tets);
    FemModel fem(scene.mesh);
    ElasticForces forces(fem, scene.energies);
    const VectorXd x = DeformedPositions(scene.mesh, 1e-3, 8);
    std::mt19937 rng(9);
    const VectorXd z = NormalVector(static_cast<int>(x.size()), &rng);
    // Two parts: even and odd elements.
    std::vector<int> part(fem.num_elements());
    std::vector<double> mu_even(fem.num_elements()), lambda_zero(fem.num_elements(), 0.0);
    for (int e = 0; e < fem.num_elements(); ++e) {
      part[e] = e % 2;
      mu_even[e] = e % 2 == 0 ? 1.0 : 0.0;
    }
    VectorXd dmu, dlambda;
    forces.PartLameDots(x, z, part, 2, &dmu, &dlambda, 1);
    VectorXd g_mu, g_lambda, g_mu_even;
    forces.EnergyAndGradient(x, LameField::Uniform(1.0, 0.0), &g_mu, 1);
    forces.EnergyAndGradient(x, LameField::Uniform(0.0, 1.0), &g_lambda, 1);
    forces.EnergyAndGradient(x, LameField::PerElement(mu_even.data(), lambda_zero.data()), &g_mu_even, 1);
    EXPECT_NEAR(dmu.sum(), z.dot(g_mu), 1e-12 * z.norm() * g_mu.norm());
    EXPECT_NEAR(dlambda.sum(), z.dot(g_lambda), 1e-12 * z.norm() * g_lambda.norm());
    EXPECT_NEAR(dmu(0), z.dot(g_mu_even), 1e-12 * z.norm() * g_mu.norm());
  }
}

// The element Hessians (batched cold SVDs, structured accumulation) are the
// derivative of the gradient: their packed product with a direction
// matches central differences of grad E, and it equals the per-sample
// stress-differential product ApplyHessian.
TEST(ElasticForcesTest, ElementHessiansAreTheGradientsDerivativeAndMatchTheSampleProduct) {
  const double mu = 7e4, lambda = 2.8e5;
  for (const Case& c : Cases()) {
    CaseBody body(c);
    ElasticForces& forces = body.forces;
    const LameField lame = LameField::Uniform(mu, lambda);
    const VectorXd x = DeformedPositions(body.scene.mesh, c.noise, 10);
    std::vector<double> blocks;
    forces.ElementHessians(x, lame, /*project_spd=*/false, &blocks, 1);
    std::vector<Mat9> dstress;
    forces.StressDifferentials(x, lame, &dstress, 1);
    std::mt19937 rng(11);
    const VectorXd dir = NormalVector(static_cast<int>(x.size()), &rng);
    VectorXd h_blocks, h_samples;
    std::vector<double> packed;
    forces.PackElementMatrices(blocks, &packed);
    forces.ApplyElementMatrices(packed, dir, &h_blocks, 1);
    forces.ApplyHessian(dstress, dir, &h_samples, 1);
    EXPECT_LE((h_blocks - h_samples).norm(), 1e-12 * h_samples.norm()) << "tets " << c.tets << " noise " << c.noise;
    const auto gradient = [&](const VectorXd& y) {
      VectorXd g;
      forces.EnergyAndGradient(y, lame, &g, 1);
      return g;
    };
    testing::DifferenceOptions options;
    options.rtol = 1e-5;
    EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(gradient, x, dir, h_blocks, options)))
        << "tets " << c.tets << " noise " << c.noise;
  }
}

TEST(ElasticForcesTest, ElementHessiansDependOnThePositionsAloneAndAreSymmetric) {
  const double mu = 7e4, lambda = 2.8e5;
  for (const bool tets : {false, true}) {
    const Scene scene = testing::SmallBeamScene(tets);
    FemModel fem(scene.mesh);
    ElasticForces a(fem, scene.energies), b(fem, scene.energies);
    const LameField lame = LameField::Uniform(mu, lambda);
    const VectorXd x = DeformedPositions(scene.mesh, 1e-3, 12);
    std::vector<double> ka, kb, k2;
    a.ElementHessians(x, lame, false, &ka, 1);
    // b evaluated elsewhere first (warm-start caches moved), then 2 threads.
    b.EnergyAndGradient(DeformedPositions(scene.mesh, 1e-2, 13), lame, nullptr, 1);
    b.ElementHessians(x, lame, false, &kb, 1);
    b.ElementHessians(x, lame, false, &k2, 2);
    EXPECT_EQ(ka, kb);
    EXPECT_EQ(ka, k2);
    const int n = 3 * fem.nodes_per_element();
    double asym = 0, scale = 0;
    for (int e = 0; e < fem.num_elements(); ++e) {
      const Eigen::Map<const Eigen::MatrixXd> k(ka.data() + static_cast<size_t>(e) * n * n, n, n);
      asym = std::max(asym, (k - k.transpose()).cwiseAbs().maxCoeff());
      scale = std::max(scale, k.cwiseAbs().maxCoeff());
    }
    EXPECT_LE(asym, 1e-12 * scale) << "tets " << tets;
  }
}

}  // namespace
}  // namespace diffpd

namespace diffpd {
namespace {

// A 3-element beam (hexahedra) or 15-18 tetrahedra: the last group of 8
// elements partly empty; its element Hessians at a deformed state, dense and
// packed (mu = 7e4, lambda = 2.8e5).
struct PartialGroupBeam {
  static constexpr double kMu = 7e4, kLambda = 2.8e5;
  PartialGroupBeam(bool tets, std::vector<ElasticEnergy> energies)
      : scene(BeamScene(tets, std::move(energies))),
        fem(scene.mesh),
        forces(fem, scene.energies),
        x(DeformedPositions(scene.mesh, 2e-3, 14)) {
    EXPECT_NE(fem.num_elements() % 8, 0);
    forces.ElementHessians(x, LameField::Uniform(kMu, kLambda), false, &blocks, 1);
    forces.PackElementMatrices(blocks, &packed);
  }
  static Scene BeamScene(bool tets, std::vector<ElasticEnergy> energies) {
    Scene s = testing::SmallBeamScene(tets, std::move(energies));
    s.mesh = tets ? testing::BoxTetMesh(3, 1, 1, 0.12, 0.04, 0.04) : testing::BoxHexMesh(3, 1, 1, 0.12, 0.04, 0.04);
    return s;
  }
  Scene scene;
  FemModel fem;
  ElasticForces forces;
  VectorXd x;
  std::vector<double> blocks, packed;
};

// Packed element Hessians built straight from x equal the dense element
// blocks packed afterwards, also when the element count leaves the last group
// of 8 partly empty (3 hexahedra; 5 tetrahedra per cube x 3 cubes = 15 or
// 6 x 3 = 18), for 1 and 2 threads. Energy sets whose differentials are all
// SVD-coefficient based take the lane-by-lane build (AddPackedSampleStiffness,
// equal to rounding); a set with a non-SVD energy takes the per-element
// build, bit for bit.
TEST(ElasticForcesTest, PackedHessiansFromPositionsMatchThePackedDenseBlocks) {
  using E = ElasticEnergy;
  const std::vector<std::vector<E>> sets = {{E::kPdCorotated, E::kPdVolume},
                                            {E::kCorotated},
                                            {E::kPdCorotated},
                                            {E::kNeoHookean},
                                            {E::kCorotated, E::kLinear}};
  for (const bool tets : {false, true}) {
    for (const auto& energies : sets) {
      PartialGroupBeam beam(tets, energies);
      ElasticForces& forces = beam.forces;
      const VectorXd& x = beam.x;
      const std::vector<double>& packed = beam.packed;
      bool all_svd = true;
      for (const E e : energies) all_svd = all_svd && internal::NeedsSvd(e);
      double largest = 0;
      for (const double v : packed) largest = std::max(largest, std::abs(v));
      for (const int threads : {1, 2}) {
        std::vector<double> direct;
        forces.PackedElementHessians(x, LameField::Uniform(PartialGroupBeam::kMu, PartialGroupBeam::kLambda), &direct,
                                     threads);
        ASSERT_EQ(direct.size(), packed.size());
        double worst = 0;
        for (size_t i = 0; i < packed.size(); ++i) worst = std::max(worst, std::abs(direct[i] - packed[i]));
        const std::string what = std::string(tets ? "tets" : "hexes") + ", " + std::to_string(energies.size()) +
                                 " energies, first " + std::to_string(static_cast<int>(energies[0])) + ", " +
                                 std::to_string(threads) + " threads";
        if (all_svd)
          EXPECT_LE(worst, 1e-13 * largest) << what;
        else
          EXPECT_EQ(direct, packed) << what;
      }
    }
  }
}

// The packed, element-interleaved product equals the dense element blocks'
// product, also for a partly empty last group.
TEST(ElasticForcesTest, PackedProductMatchesTheDenseBlocksForPartialGroups) {
  for (const bool tets : {false, true}) {
    PartialGroupBeam beam(tets, testing::SmallBeamScene(tets).energies);
    const Scene& scene = beam.scene;
    const FemModel& fem = beam.fem;
    ElasticForces& forces = beam.forces;
    const VectorXd& x = beam.x;
    const std::vector<double>& blocks = beam.blocks;
    const std::vector<double>& packed = beam.packed;
    std::mt19937 rng(15);
    const VectorXd z = NormalVector(static_cast<int>(x.size()), &rng);
    VectorXd product;
    forces.ApplyElementMatrices(packed, z, &product, 1);
    const int k = fem.nodes_per_element(), n = 3 * k;
    VectorXd expected = VectorXd::Zero(x.size());
    for (int e = 0; e < fem.num_elements(); ++e) {
      const Eigen::Map<const Eigen::MatrixXd> ke(blocks.data() + static_cast<size_t>(e) * n * n, n, n);
      VectorXd ze(n);
      for (int a = 0; a < k; ++a) ze.segment<3>(3 * a) = z.segment<3>(3 * scene.mesh.elements(a, e));
      const VectorXd ye = ke * ze;
      for (int a = 0; a < k; ++a) expected.segment<3>(3 * scene.mesh.elements(a, e)) += ye.segment<3>(3 * a);
    }
    EXPECT_LE((product - expected).norm(), 1e-13 * expected.norm()) << "tets " << tets;
  }
}

// The product of several columns in one pass over the packed matrices
// equals the single-vector product of each column bit for bit (the same
// kernel and sums per column), for tetrahedra and hexahedra with a partly
// empty last group, on 1 and 2 threads, and the single-vector product is
// unchanged by a column product made in between.
TEST(ElasticForcesTest, PackedProductOfColumnsEqualsTheProductOfEachColumn) {
  for (const bool tets : {false, true}) {
    PartialGroupBeam beam(tets, testing::SmallBeamScene(tets).energies);
    ElasticForces& forces = beam.forces;
    std::mt19937 rng(16);
    const int rows = static_cast<int>(beam.x.size()), cols = 5;
    MatrixXd z(rows, cols);
    for (int c = 0; c < cols; ++c) z.col(c) = NormalVector(rows, &rng);
    for (const int threads : {1, 2}) {
      MatrixXd product;
      forces.ApplyElementMatricesToColumns(beam.packed, z, &product, threads);
      ASSERT_EQ(product.rows(), rows);
      ASSERT_EQ(product.cols(), cols);
      for (int c = 0; c < cols; ++c) {
        VectorXd single;
        forces.ApplyElementMatrices(beam.packed, z.col(c), &single, threads);
        EXPECT_EQ((product.col(c) - single).cwiseAbs().maxCoeff(), 0.0)
            << (tets ? "tets" : "hexes") << ", column " << c << ", " << threads << " threads";
        EXPECT_GT(single.norm(), 0.0);
      }
    }
  }
}

// The unit-parameter gradients kept by the packed Hessian pass give
// PartLameDots' per-part dots (to rounding, from the same warm-start cache),
// for coefficient-form energy sets (lane-by-lane pass) and a set with a
// non-SVD energy (element-by-element pass); the warm-started pass's
// Hessians equal the cold ones to rounding.
TEST(ElasticForcesTest, UnitGradientsOfThePackedPassGiveThePartLameDots) {
  using E = ElasticEnergy;
  const std::vector<std::vector<E>> sets = {
      {E::kPdCorotated, E::kPdVolume}, {E::kNeoHookean}, {E::kCorotated, E::kLinear}};
  for (const bool tets : {false, true}) {
    for (const auto& energies : sets) {
      PartialGroupBeam beam(tets, energies);
      const int m = beam.fem.num_elements();
      std::vector<int> part(m);
      for (int e = 0; e < m; ++e) part[e] = e % 2;
      std::mt19937 rng(17);
      const VectorXd z = NormalVector(static_cast<int>(beam.x.size()), &rng);
      const LameField lame = LameField::Uniform(PartialGroupBeam::kMu, PartialGroupBeam::kLambda);
      const std::string what =
          std::string(tets ? "tets" : "hexes") + ", first energy " + std::to_string(static_cast<int>(energies[0]));
      // Both from the same cache: a fresh object each (identity guesses),
      // and again after both were moved by another state.
      ElasticForces fused(beam.fem, energies), separate(beam.fem, energies);
      for (int round = 0; round < 2; ++round) {
        if (round == 1) {
          const VectorXd other = DeformedPositions(beam.scene.mesh, 2e-3, 18);
          fused.EnergyAndGradient(other, lame, nullptr, 1);
          separate.EnergyAndGradient(other, lame, nullptr, 1);
        }
        std::vector<double> packed, gradients;
        fused.PackedElementHessians(beam.x, lame, &packed, 1, &gradients, /*warm_start=*/true);
        ASSERT_EQ(gradients.size(), static_cast<size_t>(6 * beam.fem.nodes_per_element()) * m) << what;
        VectorXd dmu, dlambda, dmu_ref, dlambda_ref;
        fused.LameDotsFromUnitGradients(gradients, z, part, 2, &dmu, &dlambda);
        separate.PartLameDots(beam.x, z, part, 2, &dmu_ref, &dlambda_ref, 1);
        VectorXd g_mu, g_lambda;
        separate.EnergyAndGradient(beam.x, LameField::Uniform(1.0, 0.0), &g_mu, 1);
        separate.EnergyAndGradient(beam.x, LameField::Uniform(0.0, 1.0), &g_lambda, 1);
        for (int p = 0; p < 2; ++p) {
          EXPECT_NEAR(dmu(p), dmu_ref(p), 1e-12 * z.norm() * g_mu.norm()) << what << ", round " << round;
          EXPECT_NEAR(dlambda(p), dlambda_ref(p), 1e-12 * z.norm() * g_lambda.norm()) << what << ", round " << round;
        }
        EXPECT_NEAR(dmu.sum(), z.dot(g_mu), 1e-12 * z.norm() * g_mu.norm()) << what;
        EXPECT_NE(dmu(0), 0.0) << what;
        double largest = 0, worst = 0;
        for (size_t i = 0; i < packed.size(); ++i) {
          largest = std::max(largest, std::abs(beam.packed[i]));
          worst = std::max(worst, std::abs(packed[i] - beam.packed[i]));
        }
        EXPECT_LE(worst, 1e-13 * largest) << what << ", round " << round;
      }
    }
  }
}

}  // namespace
}  // namespace diffpd
