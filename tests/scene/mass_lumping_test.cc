// Scene::mass_lumping (scene.h): kEqualNodes puts rho times the mean element
// volume on every node (inertia and gravity), the density gradient through a
// rollout with it matches central differences, and invalid settings are
// refused with their reason.
#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "test_scenes.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd::testing {
namespace {

TEST(MassLumpingTest, EqualNodesPutTheMeanElementMassOnEveryNode) {
  Scene scene = SmallBeamScene();
  const double volume = 0.16 * 0.04 * 0.04, rho = scene.material.density;
  const Simulator lumped(scene, TightOptions(Method::kPdLbfgs));
  EXPECT_NEAR(lumped.LumpedMass().sum() / 3, rho * volume, 1e-12 * rho * volume);
  scene.mass_lumping = MassLumping::kEqualNodes;
  const Simulator equal(scene, TightOptions(Method::kPdLbfgs));
  const VectorXd m = equal.LumpedMass();
  const double node_mass = rho * volume / scene.mesh.num_elements();
  EXPECT_NEAR(m.minCoeff(), node_mass, 1e-15 * node_mass);
  EXPECT_NEAR(m.maxCoeff(), node_mass, 1e-15 * node_mass);
  EXPECT_EQ(m.size(), scene.mesh.num_dofs());
}

TEST(MassLumpingTest, DensityGradientWithEqualNodesMatchesCentralDifferences) {
  Scene scene = SmallBeamScene();
  scene.mass_lumping = MassLumping::kEqualNodes;
  Simulator sim(scene, TightOptions(Method::kPdLbfgs));
  const int steps = 4;
  const State start = MovingStart(sim);
  const std::vector<StepInput> inputs(steps);
  std::mt19937_64 rng(7);
  const VectorXd weights = RandomVector(scene.mesh.num_dofs(), &rng, 1.0);
  const auto loss = [&](double rho) {
    MaterialParameters m = scene.material;
    m.density = rho;
    sim.SetMaterial(m);
    return weights.dot(sim.Simulate(start, inputs).states.back().x);
  };
  const double rho = scene.material.density;
  loss(rho);
  sim.SetMaterial(scene.material);
  const Rollout rollout = sim.Simulate(start, inputs);
  LossGradient dl(steps);
  dl.dx.back() = weights;
  const double analytic = sim.Backward(rollout, dl).density;
  DifferenceOptions options;
  options.noise = 1e-11;
  const DifferenceCheck c = CheckGradient([&](const VectorXd& r) { return loss(r(0)); }, VectorXd::Constant(1, rho),
                                          VectorXd::Constant(1, analytic), options);
  EXPECT_TRUE(Passes(c));
  EXPECT_NE(analytic, 0.0);
}

TEST(MassLumpingTest, InvalidSettingsAreRefused) {
  Scene scene = SmallBeamScene();
  scene.mass_lumping = static_cast<MassLumping>(7);
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                       "scene: mass_lumping = 7 is invalid: must be 0 (lumped) or 1 (equal-nodes)");
  scene = TwoRegionBeamScene();
  scene.mass_lumping = MassLumping::kEqualNodes;
  EXPECT_THROW_MESSAGE(scene.Validate(), InvalidInputError,
                       "scene: mass_lumping = equal-nodes needs a single material (" +
                           std::to_string(scene.material_regions.size()) + " material regions declared)");
  EXPECT_STREQ(ToString(MassLumping::kEqualNodes), "equal-nodes");
  EXPECT_STREQ(ToString(MassLumping::kLumped), "lumped");
  EXPECT_EQ(ParseMassLumping("equal-nodes"), MassLumping::kEqualNodes);
  EXPECT_EQ(ParseMassLumping("lumped"), MassLumping::kLumped);
  EXPECT_THROW_MESSAGE(ParseMassLumping("heavy"), InvalidInputError,
                       "masses 'heavy' is unknown: use lumped or equal-nodes");
}

}  // namespace
}  // namespace diffpd::testing
