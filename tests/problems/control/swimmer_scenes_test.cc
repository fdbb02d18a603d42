// The swimmers of the control problems: the starfish is the fact sheet's
// scene (387 nodes, 168 hexes, 344 water quads, 16 strips of 10 muscles in
// the sheet's order, the 243-value observation, the actual channel drive),
// the fish is mirror-symmetric across its mid-plane with its strips on both
// flanks and 41 observed mid-line nodes, and the swim loss's gradient is
// exact.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "control/shark_control.h"
#include "control/starfish_control.h"
#include "test_scenes.h"
#include "util/central_difference.h"

namespace diffpd::problems {
namespace {

Vec3 Centroid(const Mesh& mesh, int e) {
  Vec3 c = Vec3::Zero();
  for (int a = 0; a < 8; ++a) c += mesh.vertices.col(mesh.elements(a, e)) / 8;
  return c;
}

TEST(SwimmerScenesTest, StarfishIsTheFactSheetsScene) {
  const Swimmer s = StarfishControl().MakeSwimmer(false);
  const Mesh& mesh = s.scene.mesh;
  EXPECT_EQ(mesh.num_vertices(), 387);
  EXPECT_EQ(mesh.num_dofs(), 1161);
  EXPECT_EQ(mesh.num_elements(), 168);
  ASSERT_TRUE(s.scene.quad_hydrodynamics.has_value());
  EXPECT_EQ(s.scene.quad_hydrodynamics->quads.cols(), 344);
  EXPECT_FALSE(s.scene.gravity.has_value());
  EXPECT_TRUE(s.scene.dirichlet.dofs.empty());
  EXPECT_EQ(s.scene.energies, std::vector<ElasticEnergy>{ElasticEnergy::kPdCorotated});
  EXPECT_EQ(s.scene.material.youngs_modulus, 1e6);
  EXPECT_EQ(s.scene.material.poissons_ratio, 0.45);
  // 2.2 m tip to tip, node (11, 11, 1) at the origin.
  EXPECT_NEAR(mesh.vertices.row(0).minCoeff(), -1.1, 1e-12);
  EXPECT_NEAR(mesh.vertices.row(1).maxCoeff(), 1.1, 1e-12);
  EXPECT_EQ(mesh.vertices.col(s.observation.reference_node).norm(), 0.0);
  ASSERT_EQ(s.scene.muscles.size(), 160u);
  ASSERT_EQ(s.strips.size(), 16u);
  for (const auto& strip : s.strips) EXPECT_EQ(strip.size(), 10u);
  // P0, layer 0: the -y arm's x-cell 10, from the root (y cell 9) to the tip (0).
  const Vec3 root = Centroid(mesh, s.scene.muscles[s.strips[0][0]].elements[0]);
  const Vec3 tip = Centroid(mesh, s.scene.muscles[s.strips[0][9]].elements[0]);
  EXPECT_LT((root - Vec3(-0.05, -0.15, -0.05)).norm(), 1e-12);
  EXPECT_LT((tip - Vec3(-0.05, -1.05, -0.05)).norm(), 1e-12);
  EXPECT_EQ(s.scene.muscles[s.strips[0][0]].fibers[0], Vec3::UnitY());
  // P1, layer 1: the -x arm's y-cell 10, fibres along x.
  const Vec3 p1 = Centroid(mesh, s.scene.muscles[s.strips[3][0]].elements[0]);
  EXPECT_LT((p1 - Vec3(-0.15, -0.05, 0.05)).norm(), 1e-12);
  EXPECT_EQ(s.scene.muscles[s.strips[3][0]].fibers[0], Vec3::UnitX());
  // Channel c drives pairs 2c and 2c + 1, layer 0 on -w and layer 1 on +w.
  ASSERT_EQ(s.drives.size(), 16u);
  for (int strip = 0; strip < 16; ++strip) {
    EXPECT_EQ(s.drives[strip].channel, strip / 4) << strip;
    EXPECT_EQ(s.drives[strip].sign, strip % 2 == 0 ? -1 : 1) << strip;
  }
  EXPECT_EQ(s.observation.size(), 243);
  EXPECT_EQ(s.channels, 4);
  // The first observed node: (11, 0, 1), the -y arm's tip on the centre line.
  EXPECT_LT((mesh.vertices.col(s.observation.nodes[0]) - Vec3(0, -1.1, 0)).norm(), 1e-12);
  EXPECT_EQ(s.steps, 200);
  EXPECT_EQ(s.time_step, 3.33e-2);
  s.scene.Validate();
}

TEST(SwimmerScenesTest, FishIsMirrorSymmetricWithStripsOnBothFlanks) {
  for (const bool small : {false, true}) {
    const Swimmer s = SharkControl().MakeSwimmer(small);
    const Mesh& mesh = s.scene.mesh;
    EXPECT_EQ(mesh.num_dofs(), small ? 828 : 3972) << small;
    s.scene.Validate();
    // Every node has its mirror image across y = 0.1.
    std::map<std::array<long, 3>, int> at;
    auto key = [](const Vec3& p) {
      return std::array<long, 3>{std::lround(p.x() * 1e6), std::lround(p.y() * 1e6), std::lround(p.z() * 1e6)};
    };
    for (int v = 0; v < mesh.num_vertices(); ++v) at[key(mesh.vertices.col(v))] = v;
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      Vec3 p = mesh.vertices.col(v);
      p.y() = 0.2 - p.y();
      EXPECT_EQ(at.count(key(p)), 1u) << "node " << v;
    }
    // Strips along x, left (y < 0.1) on -w and right on +w, of equal length.
    const size_t strips = small ? 4 : 8, length = small ? 14 : 28;
    ASSERT_EQ(s.strips.size(), strips);
    for (size_t k = 0; k < strips; ++k) {
      EXPECT_EQ(s.strips[k].size(), length);
      const Vec3 first = Centroid(mesh, s.scene.muscles[s.strips[k].front()].elements[0]);
      const Vec3 last = Centroid(mesh, s.scene.muscles[s.strips[k].back()].elements[0]);
      EXPECT_LT(first.x(), last.x());  // root at the head
      EXPECT_EQ(s.drives[k].sign, first.y() < 0.1 ? -1 : 1);
      EXPECT_EQ(s.drives[k].channel, first.z() < 0 ? 0 : 1);
    }
    EXPECT_EQ(s.observation.nodes.size(), small ? 21u : 41u);
    EXPECT_LT((mesh.vertices.col(s.observation.reference_node) - Vec3(1.0, 0.1, 0.0)).norm(), 1e-12);
    EXPECT_EQ(s.loss.direction, -Vec3::UnitX());
    EXPECT_EQ(s.loss.side_weight, 10.0);
  }
}

TEST(SwimmerScenesTest, SwimLossGradientIsExact) {
  SwimLoss loss;
  loss.nodes = {0, 2};
  loss.direction = Vec3(0, 0.6, 0.8);
  loss.side_weight = 3;
  std::mt19937_64 rng(4);
  Rollout r;
  for (int k = 0; k < 3; ++k) r.states.push_back(State{VectorXd::Zero(9), testing::RandomVector(9, &rng, 1)});
  r.inputs.resize(2);
  LossGradient g;
  const double value = loss.Evaluate(r, &g);
  // By hand at step 1 and 2: vbar = (v_0 + v_2) / 2.
  double expected = 0;
  for (int k = 1; k <= 2; ++k) {
    const Vec3 mean = (r.states[k].v.segment<3>(0) + r.states[k].v.segment<3>(6)) / 2;
    const double forward = loss.direction.dot(mean);
    expected += -forward + 3 * (mean - forward * loss.direction).squaredNorm();
  }
  EXPECT_NEAR(value, expected, 1e-14);
  const auto of_v1 = [&](const VectorXd& v) {
    Rollout q = r;
    q.states[1].v = v;
    return loss.Evaluate(q, nullptr);
  };
  EXPECT_TRUE(testing::Passes(testing::CheckGradient(of_v1, r.states[1].v, g.dv[1])));
  EXPECT_EQ(g.dv[0].size(), 0);
}

}  // namespace
}  // namespace diffpd::problems
