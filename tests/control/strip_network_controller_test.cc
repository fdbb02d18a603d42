// The strip network controller: its observation, its action (positive and
// negative channel parts through the delay line), its vector-Jacobian
// products w.r.t. positions, velocities, memory and weights against central
// differences, and its input checks.
#include "diffpd/strip_network_controller.h"

#include <gtest/gtest.h>

#include <random>

#include "diffpd/error.h"
#include "test_scenes.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

using testing::RandomVector;

constexpr int kNodes = 6;

// Two strips of 3 and 2 muscles (of 6), both driven by channel 1 with
// opposite signs, one by channel 0; observation of node 2 and nodes 0, 5, 3.
StripNetworkController MakeController(std::uint64_t seed) {
  Mlp mlp({3 + 6 * 3, 8, 2}, MlpNonlinearity::kTanh, MlpNonlinearity::kTanh);
  mlp.InitializeOrthogonal(seed, 5.0 / 3.0);
  MuscleDelayLine line({{0, 1, 2}, {3, 4}, {5}}, 6);
  return StripNetworkController(mlp, NodeObservation{2, {0, 5, 3}}, line, {{1, -1}, {1, 1}, {0, 1}}, kNodes);
}

TEST(StripNetworkControllerTest, ObservesVelocityOfTheReferenceNodeRelativePositionsAndVelocities) {
  const StripNetworkController c = MakeController(1);
  std::mt19937_64 rng(2);
  State s{RandomVector(3 * kNodes, &rng, 1), RandomVector(3 * kNodes, &rng, 1)};
  const VectorXd o = c.Observe(s);
  ASSERT_EQ(o.size(), 21);
  EXPECT_EQ(Vec3(o.head<3>()), Vec3(s.v.segment<3>(6)));
  EXPECT_EQ(Vec3(o.segment<3>(6)), Vec3(s.x.segment<3>(15) - s.x.segment<3>(6)));
  EXPECT_EQ(Vec3(o.segment<3>(3 + 9 + 6)), Vec3(s.v.segment<3>(9)));
}

TEST(StripNetworkControllerTest, StripsTakeThePositiveOrNegativePartOfTheirChannel) {
  const StripNetworkController c = MakeController(1);
  std::mt19937_64 rng(2);
  State s{RandomVector(3 * kNodes, &rng, 1), RandomVector(3 * kNodes, &rng, 1)};
  const VectorXd w = c.network().Evaluate(c.Observe(s));
  const VectorXd memory = RandomVector(c.memory_size(), &rng, 0.5);
  ControlAction action;
  VectorXd next;
  c.Act(0, s, memory, &action, &next);
  EXPECT_EQ(action.external_force.size(), 0);
  ASSERT_EQ(next.size(), 6);
  EXPECT_EQ(next(0), std::max(-w(1), 0.0));
  EXPECT_EQ(next(3), std::max(w(1), 0.0));
  EXPECT_EQ(next(5), std::max(w(0), 0.0));
  EXPECT_EQ(next(1), memory(0));
  EXPECT_EQ(action.activation(4), 1 - memory(3));
  // Exactly one of a channel's two strips contracts.
  EXPECT_EQ(next(0) * next(3), 0.0);
}

TEST(StripNetworkControllerTest, VectorJacobianProductsMatchCentralDifferences) {
  const StripNetworkController c = MakeController(4);
  std::mt19937_64 rng(9);
  const State s{RandomVector(3 * kNodes, &rng, 0.3), RandomVector(3 * kNodes, &rng, 0.5)};
  const VectorXd memory = RandomVector(c.memory_size(), &rng, 0.5);
  const VectorXd g_act = RandomVector(6, &rng, 1), g_next = RandomVector(6, &rng, 1);
  // The scalar pairing of the outputs with the adjoints, as a function of
  // (x, v, memory, theta) stacked.
  const int n = 3 * kNodes, m = c.memory_size(), p = c.num_parameters();
  const auto f = [&](const VectorXd& y) {
    StripNetworkController d = c;
    d.SetParameters(y.tail(p));
    ControlAction a;
    VectorXd next;
    d.Act(0, State{y.head(n), y.segment(n, n)}, y.segment(2 * n, m), &a, &next);
    return g_act.dot(a.activation) + g_next.dot(next);
  };
  VectorXd y(2 * n + m + p);
  y << s.x, s.v, memory, c.parameters();
  VectorXd gx = VectorXd::Zero(n), gv = VectorXd::Zero(n), g_memory, g_theta = VectorXd::Zero(p);
  c.ActVjp(0, s, memory, ControlAction{g_act, VectorXd()}, g_next, &gx, &gv, &g_memory, &g_theta);
  VectorXd analytic(y.size());
  analytic << gx, gv, g_memory, g_theta;
  // Both channels away from 0 (the kink of max(., 0)) at this state.
  const VectorXd w = c.network().Evaluate(c.Observe(s));
  ASSERT_GT(w.cwiseAbs().minCoeff(), 1e-3);
  testing::DifferenceOptions options;
  options.input_scale = 0.1;  // the smallest scale the outputs change over (positions)
  EXPECT_TRUE(testing::Passes(testing::CheckGradient(f, y, analytic, options)));
}

TEST(StripNetworkControllerTest, RefusesMismatchedNetworkNodesAndDrives) {
  const Mlp mlp({3 + 6 * 2, 4, 2});
  const MuscleDelayLine line({{0, 1}, {2}}, 3);
  const NodeObservation obs{0, {1, 2}};
  EXPECT_THROW_MESSAGE(StripNetworkController(Mlp({20, 2}), obs, line, {{0, 1}, {1, 1}}, 3), InvalidInputError,
                       "StripNetworkController: the network has 20 inputs, the observation 15 values");
  EXPECT_THROW_MESSAGE(StripNetworkController(mlp, NodeObservation{0, {1, 7}}, line, {{0, 1}, {1, 1}}, 3),
                       InvalidInputError,
                       "StripNetworkController: observation.nodes[1] = 7 is out of range [0, 3) (no such node)");
  EXPECT_THROW_MESSAGE(StripNetworkController(mlp, obs, line, {{0, 1}}, 3), InvalidInputError,
                       "StripNetworkController: 1 strip drives given, expected 2 (one per strip)");
  EXPECT_THROW_MESSAGE(StripNetworkController(mlp, obs, line, {{0, 1}, {2, 1}}, 3), InvalidInputError,
                       "StripNetworkController: drives[1].channel = 2 is out of range [0, 2) (the network's outputs)");
  EXPECT_THROW_MESSAGE(StripNetworkController(mlp, obs, line, {{0, 0}, {1, 1}}, 3), InvalidInputError,
                       "StripNetworkController: drives[0].sign = 0 is invalid: must be +1 or -1");
}

}  // namespace
}  // namespace diffpd
