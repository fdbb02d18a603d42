// Adam with the original swimmers' settings: the first step moves every
// parameter by the learning rate against its gradient's sign, the gradient
// is clipped to its norm limit before the weight decay is added, the
// learning rate decays linearly, a quadratic is minimised, and bad options
// and gradients are refused.
#include "control/adam.h"

#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd::problems {
namespace {

TEST(AdamTest, FirstStepMovesEachParameterByTheLearningRateAgainstItsGradient) {
  AdamOptions o;
  o.weight_decay = 0;
  o.clip_norm = 0;
  Adam adam(o, 3);
  VectorXd theta(3), g(3);
  theta << 1, 2, 3;
  g << 0.5, -2e-3, 7;
  const double lr = adam.Step(g, &theta);
  EXPECT_EQ(lr, 1e-3);
  // m^ = g, s^ = g^2: the step is lr g / (|g| + eps).
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(theta(i), (VectorXd(3) << 1, 2, 3).finished()(i) - 1e-3 * g(i) / (std::abs(g(i)) + 1e-8), 1e-15);
}

TEST(AdamTest, ClipsTheGradientNormBeforeAddingTheWeightDecay) {
  AdamOptions o;
  o.beta1 = 0;  // the step is then lr ghat / (|ghat| + eps), ghat the processed gradient
  o.beta2 = 0;
  o.weight_decay = 0.1;
  o.clip_norm = 1.0;
  Adam adam(o, 2);
  VectorXd theta(2), g(2);
  theta << 10, -1;
  g << 3, 4;  // |g| = 5: clipped to (0.6, 0.8) / (1 + 2e-7)
  adam.Step(g, &theta);
  const double c = 1.0 / (5 + 1e-6);
  const double g0 = 3 * c + 0.1 * 10, g1 = 4 * c - 0.1;
  EXPECT_NEAR(theta(0), 10 - 1e-3 * g0 / (std::abs(g0) + 1e-8), 1e-15);
  EXPECT_NEAR(theta(1), -1 - 1e-3 * g1 / (std::abs(g1) + 1e-8), 1e-15);
}

TEST(AdamTest, LearningRateDecaysLinearlyOverTheSchedule) {
  AdamOptions o;
  o.schedule_steps = 4;
  Adam adam(o, 1);
  VectorXd theta = VectorXd::Ones(1);
  const double expected[4] = {1e-3, 0.75e-3, 0.5e-3, 0.25e-3};
  for (int e = 0; e < 4; ++e) EXPECT_DOUBLE_EQ(adam.Step(VectorXd::Ones(1), &theta), expected[e]);
  EXPECT_EQ(adam.steps_taken(), 4);
}

TEST(AdamTest, MinimisesAQuadratic) {
  AdamOptions o;
  o.learning_rate = 0.05;
  o.schedule_steps = 0;
  o.weight_decay = 0;
  Adam adam(o, 2);
  VectorXd theta(2);
  theta << 2, -3;
  for (int e = 0; e < 2000; ++e) {
    const VectorXd g = (VectorXd(2) << 2 * (theta(0) - 1), 20 * (theta(1) + 0.5)).finished();
    adam.Step(g, &theta);
  }
  EXPECT_NEAR(theta(0), 1.0, 1e-3);
  EXPECT_NEAR(theta(1), -0.5, 1e-3);
}

TEST(AdamTest, RefusesInvalidOptionsAndNonFiniteGradients) {
  AdamOptions o;
  o.beta1 = 1;
  EXPECT_THROW_MESSAGE(Adam(o, 2), InvalidInputError, "adam: beta1 = 1 is invalid: must be in [0, 1)");
  o = AdamOptions();
  o.learning_rate = 0;
  EXPECT_THROW_MESSAGE(Adam(o, 2), InvalidInputError, "adam: learning_rate = 0 is invalid: must be finite and > 0");
  o = AdamOptions();
  o.weight_decay = -1;
  EXPECT_THROW_MESSAGE(Adam(o, 2), InvalidInputError, "adam: weight_decay = -1 is invalid: must be finite and >= 0");
  Adam adam(AdamOptions(), 2);
  VectorXd theta = VectorXd::Zero(2);
  EXPECT_THROW_MESSAGE(adam.Step((VectorXd(2) << 1, NAN).finished(), &theta), InvalidInputError,
                       "adam: the gradient has a non-finite entry");
}

}  // namespace
}  // namespace diffpd::problems
