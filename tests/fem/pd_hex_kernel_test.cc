// The fused hexahedron kernel for PD energies (fem/pd_hex_kernel.h).
//
// Properties: its energy, nodal forces and written-back V equal the general
// per-sample path (signed SVD, volume projection, EvaluateDensity) for every
// combination of PD energies, including samples that leave the batched
// volume projection (inverted, large expansion) and repeated energies; it
// refuses (returns false, changes nothing) samples the batched SVD cannot
// take (not finite, zero, extreme magnitude); and ElasticForces, which uses
// it for such scenes, honours per-element Lame parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "fem/elastic_forces.h"
#include "fem/fem_model.h"
#include "fem/pd_hex_kernel.h"
#include "material/svd3.h"
#include "test_scenes.h"

namespace diffpd {
namespace {

using internal::kHexLaneGradients;
using internal::PdHexEnergyAndForces;
using internal::PdHexWeights;

// One hexahedron of a small beam with its shape gradients in both layouts.
struct Hex {
  Scene scene = testing::SmallBeamScene(false);
  internal::FemModel fem{scene.mesh};
  std::vector<double> lanes = std::vector<double>(kHexLaneGradients);
  Eigen::Matrix<double, 3, 8> rest;
  Hex() {
    for (int l = 0; l < 8; ++l)
      for (int k = 0; k < 24; ++k) lanes[k * 8 + l] = fem.grad(l)[k];
    for (int a = 0; a < 8; ++a) rest.col(a) = scene.mesh.vertices.col(scene.mesh.elements(a, 0));
  }
};

// The general path for element 0 at nodal positions xe: energy and forces.
double GeneralPath(const Hex& hex, const Eigen::Matrix<double, 3, 8>& xe, const std::vector<ElasticEnergy>& energies,
                   double mu, double lambda, Eigen::Matrix<double, 3, 8>* fe, std::vector<Mat3>* v_out) {
  double energy = 0;
  fe->setZero();
  v_out->clear();
  for (int q = 0; q < 8; ++q) {
    const Eigen::Map<const Eigen::Matrix<double, 8, 3>> g(hex.fem.grad(q));
    const Mat3 F = xe * g;
    const internal::Svd3 svd = internal::ComputeSvd3(F);
    const internal::VolumeProjection volume = internal::ProjectSingularValuesToUnitDeterminant(svd.sigma);
    Mat3 P;
    const double vol = hex.fem.sample_volume(q);
    energy += vol * internal::EvaluateDensity(energies, F, svd, mu, lambda, &P, nullptr, &volume);
    *fe += vol * P * g.transpose();
    v_out->push_back(svd.V);
  }
  return energy;
}

PdHexWeights WeightsOf(const std::vector<ElasticEnergy>& energies, double mu, double lambda) {
  PdHexWeights w;
  for (const ElasticEnergy e : energies) {
    if (e == ElasticEnergy::kPdCorotated) w.rotation += 2 * mu;
    if (e == ElasticEnergy::kPdVolume) w.volume += lambda;
  }
  return w;
}

// Element 0 of hex at xe, with outputs into fe, energy and v_cache.
internal::PdHexElement ElementOf(const Hex& hex, const Eigen::Matrix<double, 3, 8>& xe, const PdHexWeights& w,
                                 Eigen::Matrix<double, 3, 8>* fe, double* energy, std::vector<Mat3>* v_cache) {
  internal::PdHexElement element;
  element.xe = xe.data();
  element.lane_gradients = hex.lanes.data();
  element.grads = hex.fem.grad(0);
  element.sample_volume = hex.fem.sample_volumes(0);
  element.weights = w;
  element.v_cache = v_cache->data();
  element.fe = fe->data();
  element.energy = energy;
  return element;
}

// The kernel on one element with weights for `energies`, from a cold
// (identity) cache.
bool Kernel(const Hex& hex, const Eigen::Matrix<double, 3, 8>& xe, const std::vector<ElasticEnergy>& energies,
            double mu, double lambda, Eigen::Matrix<double, 3, 8>* fe, double* energy, std::vector<Mat3>* v_cache) {
  v_cache->assign(8, Mat3::Identity());
  const internal::PdHexElement element = ElementOf(hex, xe, WeightsOf(energies, mu, lambda), fe, energy, v_cache);
  return PdHexEnergyAndForces(&element, 1);
}

// Positions: the rest hexahedron under a linear map plus per-node noise.
Eigen::Matrix<double, 3, 8> Deformed(const Hex& hex, const Mat3& map, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::Matrix<double, 3, 8> xe = map * hex.rest;
  for (int a = 0; a < 8; ++a)
    for (int r = 0; r < 3; ++r) xe(r, a) += noise * normal(rng);
  return xe;
}

TEST(PdHexKernelTest, MatchesTheGeneralPathForEveryPdEnergyCombination) {
  const Hex hex;
  const double mu = 7e4, lambda = 2.8e5;
  using E = ElasticEnergy;
  const std::vector<std::vector<E>> combos = {{E::kPdCorotated},
                                              {E::kPdVolume},
                                              {E::kPdCorotated, E::kPdVolume},
                                              {E::kPdVolume, E::kPdCorotated, E::kPdVolume}};
  // Near rest; a rotation with shear; an inversion (det < 0: the volume
  // projection's scalar path); a 1.4x expansion (prod sigma > 2: scalar path).
  const Mat3 rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  Mat3 shear = Mat3::Identity();
  shear(0, 1) = 0.3;
  const std::vector<Mat3> maps = {Mat3::Identity(), rotation * shear, Vec3(1, 1, -0.8).asDiagonal(),
                                  1.4 * Mat3::Identity()};
  int seed = 1;
  for (const auto& energies : combos) {
    for (const Mat3& map : maps) {
      const Eigen::Matrix<double, 3, 8> xe = Deformed(hex, map, 2e-3, seed++);
      Eigen::Matrix<double, 3, 8> fe_ref, fe;
      std::vector<Mat3> v_ref, v;
      const double e_ref = GeneralPath(hex, xe, energies, mu, lambda, &fe_ref, &v_ref);
      double e = 0;
      ASSERT_TRUE(Kernel(hex, xe, energies, mu, lambda, &fe, &e, &v));
      EXPECT_NEAR(e, e_ref, 1e-12 * std::abs(e_ref) + 1e-300) << "seed " << seed;
      EXPECT_LE((fe - fe_ref).norm(), 1e-11 * fe_ref.norm()) << "seed " << seed;
      for (int q = 0; q < 8; ++q) EXPECT_LE((v[q] - v_ref[q]).norm(), 1e-12) << "sample " << q;
    }
  }
}

TEST(PdHexKernelTest, RefusesSamplesTheBatchedSvdCannotTakeAndChangesNothing) {
  const Hex hex;
  const std::vector<ElasticEnergy> energies = {ElasticEnergy::kPdCorotated, ElasticEnergy::kPdVolume};
  const Eigen::Matrix<double, 3, 8> good = Deformed(hex, Mat3::Identity(), 1e-3, 3);
  std::vector<Eigen::Matrix<double, 3, 8>> bad(4, good);
  bad[0](1, 4) = std::numeric_limits<double>::quiet_NaN();
  bad[1](2, 7) = std::numeric_limits<double>::infinity();
  bad[2].setZero();            // all nodes at the origin: F = 0
  bad[3] = 1e-120 * hex.rest;  // entries below 1e-100
  for (size_t i = 0; i < bad.size(); ++i) {
    Eigen::Matrix<double, 3, 8> fe = Eigen::Matrix<double, 3, 8>::Constant(7.0);
    double energy = 7.0;
    std::vector<Mat3> v;
    EXPECT_FALSE(Kernel(hex, bad[i], energies, 7e4, 2.8e5, &fe, &energy, &v)) << "case " << i;
    EXPECT_EQ(energy, 7.0);
    EXPECT_TRUE((fe.array() == 7.0).all());
    for (const Mat3& vq : v) EXPECT_TRUE(vq.isIdentity(0.0));
  }
}

// A batch of two elements (different states and weights) gives each the
// result of its own call.
TEST(PdHexKernelTest, TwoElementsInOneCallMatchSeparateCalls) {
  const Hex hex;
  using E = ElasticEnergy;
  const Mat3 rotation = Eigen::AngleAxisd(0.4, Vec3(0, 1, 1).normalized()).toRotationMatrix();
  const Eigen::Matrix<double, 3, 8> xa = Deformed(hex, rotation, 2e-3, 11),
                                    xb = Deformed(hex, 0.9 * Mat3::Identity(), 3e-3, 12);
  const PdHexWeights wa = WeightsOf({E::kPdCorotated, E::kPdVolume}, 7e4, 2.8e5);
  const PdHexWeights wb = WeightsOf({E::kPdCorotated, E::kPdVolume}, 3e5, 0.0);  // nu = 0: no volume weight
  Eigen::Matrix<double, 3, 8> fa, fb, fa1, fb1;
  double ea = 0, eb = 0, ea1 = 0, eb1 = 0;
  std::vector<Mat3> va(8, Mat3::Identity()), vb(8, Mat3::Identity()), va1 = va, vb1 = vb;
  const internal::PdHexElement both[2] = {ElementOf(hex, xa, wa, &fa, &ea, &va), ElementOf(hex, xb, wb, &fb, &eb, &vb)};
  ASSERT_TRUE(PdHexEnergyAndForces(both, 2));
  const internal::PdHexElement a = ElementOf(hex, xa, wa, &fa1, &ea1, &va1),
                               b = ElementOf(hex, xb, wb, &fb1, &eb1, &vb1);
  ASSERT_TRUE(PdHexEnergyAndForces(&a, 1));
  ASSERT_TRUE(PdHexEnergyAndForces(&b, 1));
  EXPECT_NEAR(ea, ea1, 1e-14 * ea1);
  EXPECT_NEAR(eb, eb1, 1e-14 * eb1);
  EXPECT_LE((fa - fa1).norm(), 1e-14 * fa1.norm());
  EXPECT_LE((fb - fb1).norm(), 1e-14 * fb1.norm());
  for (int q = 0; q < 8; ++q) {
    EXPECT_LE((va[q] - va1[q]).norm(), 1e-15);
    EXPECT_LE((vb[q] - vb1[q]).norm(), 1e-15);
  }
}

// ElasticForces takes the kernel for hexahedra with PD energies; with a
// per-element Lame field each element's energy uses its own parameters.
TEST(PdHexKernelTest, ElasticForcesUsesEachElementsLameParameters) {
  const Scene scene = testing::SmallBeamScene(false);
  internal::FemModel fem(scene.mesh);
  internal::ElasticForces forces(fem, scene.energies);
  const int m = fem.num_elements();
  std::vector<double> mu(m), lambda(m);
  for (int e = 0; e < m; ++e) {
    mu[e] = 5e4 * (1 + e);
    lambda[e] = 1e5 * (m - e);
  }
  VectorXd x(scene.mesh.num_dofs());
  std::mt19937 rng(4);
  std::normal_distribution<double> normal;
  for (int i = 0; i < x.size(); ++i) x(i) = scene.mesh.vertices(i % 3, i / 3) + 2e-3 * normal(rng);
  VectorXd grad;
  const double energy =
      forces.EnergyAndGradient(x, internal::LameField::PerElement(mu.data(), lambda.data()), &grad, 1);
  double expected = 0;
  VectorXd expected_grad = VectorXd::Zero(x.size());
  for (int e = 0; e < m; ++e) {
    Eigen::Matrix<double, 3, 8> xe;
    for (int a = 0; a < 8; ++a) xe.col(a) = x.segment<3>(3 * scene.mesh.elements(a, e));
    for (int q = 0; q < 8; ++q) {
      const int s = 8 * e + q;
      const Eigen::Map<const Eigen::Matrix<double, 8, 3>> g(fem.grad(s));
      Mat3 P;
      expected +=
          fem.sample_volume(s) * internal::EvaluateDensity(scene.energies, Mat3(xe * g), mu[e], lambda[e], &P, nullptr);
      const Eigen::Matrix<double, 3, 8> f = fem.sample_volume(s) * P * g.transpose();
      for (int a = 0; a < 8; ++a) expected_grad.segment<3>(3 * scene.mesh.elements(a, e)) += f.col(a);
    }
  }
  EXPECT_NEAR(energy, expected, 1e-12 * expected);
  EXPECT_LE((grad - expected_grad).norm(), 1e-11 * expected_grad.norm());
}

}  // namespace
}  // namespace diffpd
