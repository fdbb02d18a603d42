// Penalty contact (w/2) min(0, n . x - offset)^2: zero outside the wall,
// gradient and Hessian vs finite differences, the PD term is w on the
// diagonal, and a body settling on a penalty floor is carried by it.
#include <gtest/gtest.h>

#include <random>

#include "diffpd/simulator.h"
#include "fem/fem_model.h"
#include "fem/penalty_contact_energy.h"
#include "test_scenes.h"
#include "util/central_difference.h"

namespace diffpd {
namespace {

TEST(PenaltyContactEnergyTest, ConformsToItsEnergyGradientHessianAndPdTerm) {
  const Mesh mesh = testing::BoxHexMesh(2, 1, 1, 0.1, 0.05, 0.05);
  internal::FemModel fem(mesh);
  PenaltyContact wall;
  wall.normal = Vec3(0.3, 0, 1);
  wall.offset = 0.005;
  wall.stiffness = 500;
  for (int i = 0; i < mesh.num_vertices(); ++i) wall.nodes.push_back(i);
  internal::PenaltyContactEnergy energy(fem, {wall});
  const int n = mesh.num_dofs();
  VectorXd x = Eigen::Map<const VectorXd>(mesh.vertices.data(), n);
  // Lifted clear of the wall: no energy, no force.
  VectorXd lifted = x;
  for (int i = 0; i < mesh.num_vertices(); ++i) lifted(3 * i + 2) += 0.01;
  VectorXd grad = VectorXd::Zero(n);
  EXPECT_EQ(energy.AddEnergyAndGradient(lifted, &grad), 0.0);
  EXPECT_EQ(grad.norm(), 0.0);
  // Some nodes inside: derivatives vs finite differences.
  std::mt19937_64 rng(1);
  std::normal_distribution<double> normal(0.0, 0.002);
  for (int d = 0; d < n; ++d) x(d) += normal(rng);
  const Vec3 nh = wall.normal.normalized();
  double expected = 0;
  int inside = 0;
  for (int i = 0; i < mesh.num_vertices(); ++i) {
    const double gap = nh.dot(x.segment<3>(3 * i)) - wall.offset;
    if (gap < 0) {
      expected += 0.5 * wall.stiffness * gap * gap;
      ++inside;
    }
  }
  ASSERT_GT(inside, 0);
  grad.setZero();
  EXPECT_NEAR(energy.AddEnergyAndGradient(x, &grad), expected, 1e-15);
  VectorXd dir(n);
  for (int d = 0; d < n; ++d) dir(d) = normal(rng) / 0.002;
  const auto e = [&](const VectorXd& y) { return energy.AddEnergyAndGradient(y, nullptr); };
  const auto g = [&](const VectorXd& y) {
    VectorXd out = VectorXd::Zero(n);
    energy.AddEnergyAndGradient(y, &out);
    return out;
  };
  VectorXd hd = VectorXd::Zero(n);
  energy.AddHessianProduct(x, dir, &hd);
  EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(e, x, dir, grad.dot(dir))));
  EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(g, x, dir, hd)));
  // Element blocks assemble to the same Hessian.
  const int nb = 24;
  std::vector<double> blocks(static_cast<size_t>(mesh.num_elements()) * nb * nb, 0.0);
  energy.AddElementHessians(x, &blocks);
  VectorXd assembled = VectorXd::Zero(n);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Eigen::Map<const MatrixXd> ke(blocks.data() + static_cast<size_t>(e) * nb * nb, nb, nb);
    VectorXd ze(nb);
    for (int p = 0; p < nb; ++p) ze(p) = dir(3 * mesh.elements(p / 3, e) + p % 3);
    const VectorXd ye = ke * ze;
    for (int p = 0; p < nb; ++p) assembled(3 * mesh.elements(p / 3, e) + p % 3) += ye(p);
  }
  EXPECT_LT((assembled - hd).norm(), 1e-12 * hd.norm());
  VectorXd diagonal = VectorXd::Zero(mesh.num_vertices());
  energy.AddPdDiagonal(&diagonal);
  EXPECT_EQ(diagonal, VectorXd::Constant(mesh.num_vertices(), 500.0));
}

class PenaltyFloorTest : public ::testing::TestWithParam<Method> {};

TEST_P(PenaltyFloorTest, BodyReleasedOnAPenaltyFloorSettlesWithTheFloorCarryingItsWeight) {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(2, 2, 1, 0.1, 0.1, 0.05);
  scene.material.youngs_modulus = 1e6;
  scene.gravity = Vec3(0, 0, -9.81);
  PenaltyContact floor;
  floor.stiffness = 1e4;
  for (int i = 0; i < scene.mesh.num_vertices(); ++i)
    if (scene.mesh.vertices(2, i) < 1e-9) floor.nodes.push_back(i);
  scene.penalty_contacts = {floor};
  SolverOptions options;
  options.method = GetParam();
  options.rel_tolerance = 1e-10;
  Simulator sim(scene, options);
  // Released from rest on the floor: it sinks until the penalty forces carry its weight.
  State s = sim.RestState();
  for (int k = 0; k < 200; ++k) s = sim.Step(s, StepInput());
  const double weight = sim.LumpedMass().sum() / 3 * 9.81;
  double support = 0, depth = 0;
  for (const int i : floor.nodes) {
    support += -floor.stiffness * std::min(0.0, s.x(3 * i + 2));
    depth = std::max(depth, -s.x(3 * i + 2));
  }
  EXPECT_LT(s.v.cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_NEAR(support, weight, 1e-4 * weight);
  // Nine floor nodes share the weight; the deepest sinks by about its share / w.
  EXPECT_GT(depth, weight / 9 / floor.stiffness);
  EXPECT_LT(depth, weight / 2 / floor.stiffness);
}

INSTANTIATE_TEST_SUITE_P(Methods, PenaltyFloorTest, ::testing::Values(Method::kPd, Method::kNewtonCholesky),
                         [](const ::testing::TestParamInfo<Method>& info) {
                           return info.param == Method::kPd ? std::string("pd") : std::string("newton_cholesky");
                         });

}  // namespace
}  // namespace diffpd
