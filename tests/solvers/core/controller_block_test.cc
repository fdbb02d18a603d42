// ControllerBlock: a controller's weights as the rollout core's parameters.
// The rollout function's gradient w.r.t. the weights is the simulator's
// closed-loop reverse pass bit for bit and matches central differences of
// whole closed-loop rollouts along a random direction; the block starts
// from the controller's weights, rules out forward mode, and a second
// controller block is refused with its message.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "diffpd/solvers/core/controller_block.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "diffpd/solvers/core/trajectory_function.h"
#include "diffpd/strip_network_controller.h"
#include "test_scenes.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd::solvers {
namespace {

constexpr int kSteps = 6;

// A free 4 x 1 x 2 hex bar (0.4 x 0.1 x 0.2 m) with a muscle strip along x
// in each layer, driven by a small network (the tip nodes' observation,
// 8 hidden units, one channel: bottom layer by its negative part, top by
// its positive part).
struct Bar {
  Scene scene;
  std::vector<std::vector<int>> strips;
};

Bar MakeBar() {
  Bar b;
  b.scene.mesh = testing::BoxHexMesh(4, 1, 2, 0.4, 0.1, 0.2);
  b.scene.material = MaterialParameters{1e5, 0.4, 1e3};
  b.scene.energies = {ElasticEnergy::kPdCorotated};
  std::vector<MuscleStrip> strips(2);
  for (int layer = 0; layer < 2; ++layer) {
    for (int e = 0; e < b.scene.mesh.num_elements(); ++e) {
      Vec3 c = Vec3::Zero();
      for (int a = 0; a < 8; ++a) c += b.scene.mesh.vertices.col(b.scene.mesh.elements(a, e)) / 8;
      if ((c.z() > 0.1) == (layer == 1)) strips[layer].elements.push_back(e);
    }
    std::sort(strips[layer].elements.begin(), strips[layer].elements.end(), [&](int p, int q) {
      return b.scene.mesh.vertices(0, b.scene.mesh.elements(0, p)) <
             b.scene.mesh.vertices(0, b.scene.mesh.elements(0, q));
    });
  }
  b.strips = AddMuscleStrips(&b.scene, strips);
  return b;
}

StripNetworkController MakeController(const Bar& b) {
  const NodeObservation obs{0, {4, 9, 14}};
  Mlp mlp({obs.size(), 8, 1}, MlpNonlinearity::kTanh, MlpNonlinearity::kTanh);
  mlp.InitializeOrthogonal(7, 5.0 / 3.0);
  const int muscles = static_cast<int>(b.scene.muscles.size());
  return StripNetworkController(mlp, obs, MuscleDelayLine(b.strips, muscles), {{0, -1}, {0, 1}},
                                b.scene.mesh.num_vertices());
}

SolverOptions Options() {
  SolverOptions o;
  o.method = Method::kNewtonCholesky;
  o.time_step = 1e-2;
  o.rel_tolerance = 1e-12;
  o.abs_tolerance = 1e-12;
  o.num_threads = 1;
  return o;
}

// How far the bar's tip nodes travel along z.
std::unique_ptr<TrajectoryFunction> TipTravel(const Scene& scene) {
  return std::make_unique<PointTravel>(MeanOf(scene.mesh.num_vertices(), {4, 9, 14}), 0, kFinalState, Vec3::UnitZ(),
                                       "tip_travel");
}

TEST(ControllerBlockTest, GradientIsTheSimulatorsClosedLoopReversePassBitForBit) {
  const Bar bar = MakeBar();
  const StripNetworkController controller = MakeController(bar);
  RolloutFunction f(bar.scene, Options(), kSteps);
  f.AddBlock(std::make_unique<ControllerBlock>(controller));
  f.AddFunctional(TipTravel(bar.scene));
  VectorXd gradient;
  double value = 0;
  ASSERT_TRUE(f.Gradient(f.initial_parameters(), VectorXd::Ones(1), &gradient, &value)) << f.statistics().last_error;

  Simulator sim(bar.scene, Options());
  const Rollout rollout = sim.Simulate(sim.RestState(), controller, kSteps);
  const std::unique_ptr<TrajectoryFunction> travel = TipTravel(bar.scene);
  LossGradient loss(kSteps);
  travel->AddGradient(rollout, 1.0, &loss);
  const RolloutGradient g = sim.Backward(rollout, loss, controller);
  EXPECT_EQ(value, travel->Value(rollout));
  ASSERT_EQ(gradient.size(), g.controller_parameters.size());
  EXPECT_TRUE(gradient == g.controller_parameters);
  EXPECT_GT(gradient.norm(), 0.0);
}

TEST(ControllerBlockTest, GradientMatchesCentralDifferencesOfClosedLoopRollouts) {
  const Bar bar = MakeBar();
  RolloutFunction f(bar.scene, Options(), kSteps);
  f.AddBlock(std::make_unique<ControllerBlock>(MakeController(bar)));
  f.AddFunctional(TipTravel(bar.scene));
  const VectorXd p = f.initial_parameters();
  VectorXd gradient;
  ASSERT_TRUE(f.Gradient(p, VectorXd::Ones(1), &gradient)) << f.statistics().last_error;
  std::mt19937_64 rng(3);
  const VectorXd d = testing::RandomVector(p.size(), &rng, 1.0);
  const auto value = [&f](const VectorXd& q) {
    VectorXd v;
    EXPECT_TRUE(f.Evaluate(q, {0}, &v, nullptr)) << f.statistics().last_error;
    return v(0);
  };
  testing::DifferenceOptions options;
  options.noise = 1e-12;  // the rollouts' tolerance
  options.input_scale = 1.0;
  options.rtol = 1e-5;
  EXPECT_TRUE(testing::Passes(testing::CheckDirectionalDerivative(value, p, d, gradient.dot(d), options)));
}

TEST(ControllerBlockTest, StartsFromTheControllersWeightsWithoutForwardMode) {
  const Bar bar = MakeBar();
  const StripNetworkController controller = MakeController(bar);
  RolloutFunction f(bar.scene, Options(), kSteps);
  f.AddBlock(std::make_unique<ControllerBlock>(controller));
  f.AddFunctional(TipTravel(bar.scene));
  EXPECT_TRUE(f.initial_parameters() == controller.parameters());
  EXPECT_FALSE(f.ForwardModeAvailable());
  EXPECT_EQ(f.ResolvedMode(1000), DerivativeMode::kReverse);
  const Rollout* rollout = f.RolloutAt(f.initial_parameters());
  ASSERT_NE(rollout, nullptr);
  EXPECT_TRUE(rollout->closed_loop());
}

TEST(ControllerBlockTest, RefusesASecondControllerBlock) {
  const Bar bar = MakeBar();
  RolloutFunction f(bar.scene, Options(), kSteps);
  f.AddBlock(std::make_unique<ControllerBlock>(MakeController(bar)));
  f.AddBlock(std::make_unique<ControllerBlock>(MakeController(bar)));
  f.AddFunctional(TipTravel(bar.scene));
  EXPECT_FALSE(f.Evaluate(f.initial_parameters()));
  EXPECT_EQ(f.statistics().last_error,
            "rollout rejected: controller: the setup has a controller already; a rollout takes one ControllerBlock");
}

}  // namespace
}  // namespace diffpd::solvers
