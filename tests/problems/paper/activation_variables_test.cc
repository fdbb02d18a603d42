// The paper rows' activation maps (paper/activation_variables.h): values of
// the windowed interpolation and the gait, and their error messages.
#include "paper/activation_variables.h"

#include <gtest/gtest.h>

#include <cmath>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

solvers::RolloutSetup EmptySetup(int steps) {
  solvers::RolloutSetup setup;
  setup.inputs.resize(steps);
  return setup;
}

TEST(ActivationVariablesTest, WindowedInterpolatesWithinAWindowAndHoldsTheLastOne) {
  // Groups drive muscles 1 and 0 of 3; 10 steps in windows of 5: 2 frames.
  const WindowedActivationVariables block({1, 0}, 3, 10, 5);
  ASSERT_EQ(block.size(), 4);
  const Eigen::Vector4d x(0.2, 0.4, 1.2, 1.6);  // frame 0: (g0, g1), frame 1: (g0, g1)
  solvers::RolloutSetup setup = EmptySetup(10);
  block.Apply(x, &setup);
  // Step 3: window 0, t = 3/5.
  EXPECT_DOUBLE_EQ(setup.inputs[3].activation(1), 0.4 * 0.2 + 0.6 * 1.2);
  EXPECT_DOUBLE_EQ(setup.inputs[3].activation(0), 0.4 * 0.4 + 0.6 * 1.6);
  EXPECT_EQ(setup.inputs[3].activation(2), 1.0);  // not driven: rest
  // Steps 5..9: the last window is constant.
  EXPECT_EQ(setup.inputs[8].activation(1), 1.2);
  EXPECT_EQ(setup.inputs[8].activation(0), 1.6);
}

TEST(ActivationVariablesTest, GaitIsPeakTimesOnePlusOrMinusAmplitudeSineOverTwo) {
  const GaitActivationVariables block({{0, true, true}, {1, true, false}, {2, false, true}}, 3, 6, 1.49);
  const Eigen::Vector3d x(0.5, 0.25, 0.3);  // A_f, A_b, w
  solvers::RolloutSetup setup = EmptySetup(6);
  block.Apply(x, &setup);
  const double s = std::sin(0.3 * 4);
  EXPECT_DOUBLE_EQ(setup.inputs[4].activation(0), 1.49 * (1 + 0.5 * s) / 2);
  EXPECT_DOUBLE_EQ(setup.inputs[4].activation(1), 1.49 * (1 - 0.5 * s) / 2);
  EXPECT_DOUBLE_EQ(setup.inputs[4].activation(2), 1.49 * (1 + 0.25 * s) / 2);
}

TEST(ActivationVariablesTest, WindowedRefusesStepsThatAreNotAMultipleOfTheWindow) {
  try {
    WindowedActivationVariables({0}, 1, 12, 5);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(),
                 "windowed_activation: num_steps = 12 is invalid: must be a positive multiple of window = 5 (>= 1)");
  }
}

TEST(ActivationVariablesTest, ConstantActivationRefusesAMuscleOutOfRange) {
  try {
    ConstantActivationVariables({0, 4}, 4);
    FAIL() << "expected InvalidInputError";
  } catch (const InvalidInputError& e) {
    EXPECT_STREQ(e.what(), "constant_activation: muscle 4 is out of range [0, 4)");
  }
}

}  // namespace
}  // namespace diffpd::problems
