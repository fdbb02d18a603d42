// Muscle strips: one single-element muscle per strip element, and the delay
// line that shifts contractions from root to tip (values, its exact
// vector-Jacobian product, muscles outside strips at rest, input checks).
#include "diffpd/muscle_strip.h"

#include <gtest/gtest.h>

#include <random>

#include "diffpd/error.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

TEST(MuscleStripTest, AddsOneSingleElementMusclePerStripElementInRootToTipOrder) {
  Scene scene;
  scene.mesh = testing::BoxHexMesh(3, 1, 2, 0.3, 0.1, 0.2);
  scene.muscles.push_back(Muscle{{0}, {Vec3::UnitZ()}, 1e4});  // an existing muscle keeps its index
  const std::vector<MuscleStrip> strips = {{{4, 2, 0}, Vec3(2, 0, 0), 3e5}, {{1, 3}, Vec3::UnitY(), 1e5}};
  const std::vector<std::vector<int>> muscles = AddMuscleStrips(&scene, strips);
  ASSERT_EQ(muscles, (std::vector<std::vector<int>>{{1, 2, 3}, {4, 5}}));
  ASSERT_EQ(scene.muscles.size(), 6u);
  EXPECT_EQ(scene.muscles[2].elements, std::vector<int>{2});
  EXPECT_EQ(scene.muscles[2].fibers[0], Vec3(2, 0, 0));
  EXPECT_EQ(scene.muscles[2].stiffness, 3e5);
  EXPECT_EQ(scene.muscles[5].elements, std::vector<int>{3});
  scene.Validate();
  EXPECT_THROW_MESSAGE(AddMuscleStrips(&scene, {strips[0], MuscleStrip{}}), InvalidInputError,
                       "AddMuscleStrips: strips[1] has no elements");
  EXPECT_EQ(scene.muscles.size(), 6u);  // nothing added on error
}

TEST(MuscleStripTest, DelayLineShiftsContractionsFromRootToTipAndActivatesOneMinusThem) {
  // Strips {3, 1, 0} and {4}; muscle 2 in no strip.
  const MuscleDelayLine line({{3, 1, 0}, {4}}, 5);
  ASSERT_EQ(line.memory_size(), 4);
  EXPECT_EQ(line.strip_offset(1), 3);
  EXPECT_EQ(line.slot_muscle(0), 3);
  VectorXd memory(4), next, activation;
  memory << 0.1, 0.2, 0.3, 0.4;
  line.Advance(memory, Eigen::Vector2d(0.7, 0.9), &next, &activation);
  VectorXd expected_next(4), expected_activation(5);
  expected_next << 0.7, 0.1, 0.2, 0.9;
  expected_activation << 1 - 0.2, 1 - 0.1, 1.0, 1 - 0.7, 1 - 0.9;
  EXPECT_EQ(next, expected_next);
  EXPECT_TRUE(activation.isApprox(expected_activation, 1e-15));
}

TEST(MuscleStripTest, DelayLineVectorJacobianProductIsTheTransposeOfItsLinearMap) {
  const MuscleDelayLine line({{3, 1, 0}, {4, 2}}, 5);
  std::mt19937_64 rng(5);
  const VectorXd memory = testing::RandomVector(5, &rng, 1), u = testing::RandomVector(2, &rng, 1);
  const VectorXd g_act = testing::RandomVector(5, &rng, 1), g_next = testing::RandomVector(5, &rng, 1);
  VectorXd g_memory, g_u;
  line.AdvanceVjp(g_act, g_next, &g_memory, &g_u);
  // The map is affine: the pairing with the adjoint must equal the pairing
  // of the outputs' change along any input change (exactly, up to rounding).
  const VectorXd dm = testing::RandomVector(5, &rng, 1), du = testing::RandomVector(2, &rng, 1);
  VectorXd n0, a0, n1, a1;
  line.Advance(memory, u, &n0, &a0);
  line.Advance(memory + dm, u + du, &n1, &a1);
  const double lhs = g_act.dot(a1 - a0) + g_next.dot(n1 - n0);
  EXPECT_NEAR(lhs, g_memory.dot(dm) + g_u.dot(du), 1e-14);
  // Empty gradients are zero.
  line.AdvanceVjp(VectorXd(), VectorXd(), &g_memory, &g_u);
  EXPECT_EQ(g_memory.norm() + g_u.norm(), 0.0);
}

TEST(MuscleStripTest, DelayLineRefusesEmptyStripsAndMusclesOutOfRangeOrRepeated) {
  EXPECT_THROW_MESSAGE(MuscleDelayLine({{0}, {}}, 3), InvalidInputError, "MuscleDelayLine: strip 1 has no muscles");
  EXPECT_THROW_MESSAGE(MuscleDelayLine({{0, 3}}, 3), InvalidInputError,
                       "MuscleDelayLine: strip 0 lists muscle 3, out of range [0, 3)");
  EXPECT_THROW_MESSAGE(MuscleDelayLine({{0, 1}, {2, 1}}, 3), InvalidInputError,
                       "MuscleDelayLine: strip 1 lists muscle 1 which is already in a strip");
}

}  // namespace
}  // namespace diffpd
