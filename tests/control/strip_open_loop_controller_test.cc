// The strip open-loop controller: its action (tanh of the step's values,
// positive and negative channel parts through the delay line, independent of
// the state), its vector-Jacobian products w.r.t. memory and values against
// central differences, and its input checks.
#include "diffpd/strip_open_loop_controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "diffpd/error.h"
#include "test_scenes.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

using testing::RandomVector;

constexpr int kSteps = 3;

// Two strips of 3 and 2 muscles (of 6), both driven by channel 1 with
// opposite signs, one by channel 0.
StripOpenLoopController MakeController(std::uint64_t seed) {
  StripOpenLoopController c(kSteps, 2, MuscleDelayLine({{0, 1, 2}, {3, 4}, {5}}, 6), {{1, -1}, {1, 1}, {0, 1}});
  std::mt19937_64 rng(seed);
  c.SetParameters(RandomVector(c.num_parameters(), &rng, 1.5));
  return c;
}

TEST(StripOpenLoopControllerTest, StepTakesTheTanhOfItsValuesWhateverTheState) {
  const StripOpenLoopController c = MakeController(1);
  ASSERT_EQ(c.num_parameters(), kSteps * 2);
  std::mt19937_64 rng(2);
  const VectorXd memory = RandomVector(c.memory_size(), &rng, 0.5);
  const State s1{RandomVector(6, &rng, 1), RandomVector(6, &rng, 1)};
  const State s2{RandomVector(6, &rng, 1), RandomVector(6, &rng, 1)};
  const int step = 2;
  const VectorXd w = c.ChannelValues(step);
  EXPECT_EQ(w(1), std::tanh(c.parameters()(2 * step + 1)));
  ControlAction a1, a2;
  VectorXd next1, next2;
  c.Act(step, s1, memory, &a1, &next1);
  c.Act(step, s2, memory, &a2, &next2);
  EXPECT_EQ(a1.activation, a2.activation);
  EXPECT_EQ(next1, next2);
  EXPECT_EQ(a1.external_force.size(), 0);
  EXPECT_EQ(next1(0), std::max(-w(1), 0.0));
  EXPECT_EQ(next1(3), std::max(w(1), 0.0));
  EXPECT_EQ(next1(5), std::max(w(0), 0.0));
  EXPECT_EQ(next1(1), memory(0));
  EXPECT_EQ(a1.activation(4), 1 - memory(3));
  // Exactly one of a channel's two strips contracts.
  EXPECT_EQ(next1(0) * next1(3), 0.0);
}

TEST(StripOpenLoopControllerTest, VectorJacobianProductsMatchCentralDifferences) {
  const StripOpenLoopController c = MakeController(4);
  std::mt19937_64 rng(9);
  const State s{RandomVector(6, &rng, 0.3), RandomVector(6, &rng, 0.5)};
  const VectorXd memory = RandomVector(c.memory_size(), &rng, 0.5);
  const VectorXd g_act = RandomVector(6, &rng, 1), g_next = RandomVector(6, &rng, 1);
  const int m = c.memory_size(), p = c.num_parameters();
  for (int step = 0; step < kSteps; ++step) {
    // Every channel away from 0 (the kink of max(., 0)) at this step.
    ASSERT_GT(c.ChannelValues(step).cwiseAbs().minCoeff(), 1e-3);
    // The scalar pairing of the outputs with the adjoints, as a function of
    // (memory, theta) stacked.
    const auto f = [&](const VectorXd& y) {
      StripOpenLoopController d = c;
      d.SetParameters(y.tail(p));
      ControlAction a;
      VectorXd next;
      d.Act(step, s, y.head(m), &a, &next);
      return g_act.dot(a.activation) + g_next.dot(next);
    };
    VectorXd y(m + p);
    y << memory, c.parameters();
    VectorXd gx = VectorXd::Zero(6), gv = VectorXd::Zero(6), g_memory, g_theta = VectorXd::Zero(p);
    c.ActVjp(step, s, memory, ControlAction{g_act, VectorXd()}, g_next, &gx, &gv, &g_memory, &g_theta);
    EXPECT_EQ(gx, VectorXd::Zero(6));
    EXPECT_EQ(gv, VectorXd::Zero(6));
    // Only this step's values get a gradient.
    for (int k = 0; k < kSteps; ++k) {
      if (k != step) {
        EXPECT_EQ(g_theta.segment(2 * k, 2), VectorXd::Zero(2)) << "step " << step << ", values of " << k;
      }
    }
    VectorXd analytic(m + p);
    analytic << g_memory, g_theta;
    EXPECT_TRUE(testing::Passes(testing::CheckGradient(f, y, analytic, testing::DifferenceOptions())))
        << "step " << step;
  }
}

TEST(StripOpenLoopControllerTest, RefusesBadSizesDrivesStepsAndValues) {
  const MuscleDelayLine line({{0, 1}, {2}}, 3);
  EXPECT_THROW_MESSAGE(StripOpenLoopController(0, 2, line, {{0, 1}, {1, 1}}), InvalidInputError,
                       "StripOpenLoopController: steps = 0 is invalid: must be >= 1");
  EXPECT_THROW_MESSAGE(StripOpenLoopController(4, 0, line, {{0, 1}, {1, 1}}), InvalidInputError,
                       "StripOpenLoopController: channels = 0 is invalid: must be >= 1");
  EXPECT_THROW_MESSAGE(StripOpenLoopController(4, 2, line, {{0, 1}}), InvalidInputError,
                       "StripOpenLoopController: 1 strip drives given, expected 2 (one per strip)");
  EXPECT_THROW_MESSAGE(StripOpenLoopController(4, 2, line, {{0, 1}, {2, 1}}), InvalidInputError,
                       "StripOpenLoopController: drives[1].channel = 2 is out of range [0, 2) (the channels)");
  EXPECT_THROW_MESSAGE(StripOpenLoopController(4, 2, line, {{0, 0}, {1, 1}}), InvalidInputError,
                       "StripOpenLoopController: drives[0].sign = 0 is invalid: must be +1 or -1");
  StripOpenLoopController c(4, 2, line, {{0, 1}, {1, -1}});
  EXPECT_EQ(c.parameters(), VectorXd::Zero(8));
  EXPECT_THROW_MESSAGE(c.SetParameters(VectorXd::Zero(3)), InvalidInputError,
                       "StripOpenLoopController: parameters have 3 entries, expected 8");
  VectorXd bad = VectorXd::Zero(8);
  bad(5) = NAN;
  EXPECT_THROW_MESSAGE(c.SetParameters(bad), InvalidInputError,
                       "StripOpenLoopController: parameters have a non-finite entry");
  ControlAction a;
  VectorXd next;
  EXPECT_THROW_MESSAGE(c.Act(4, State{VectorXd::Zero(9), VectorXd::Zero(9)}, VectorXd::Zero(3), &a, &next),
                       InvalidInputError,
                       "StripOpenLoopController: step 4 is out of range [0, 4) (the steps it has values for)");
}

}  // namespace
}  // namespace diffpd
