// Every paper row's gradient dL/dx (variable map, rollout, loss) agrees with
// central differences on its small instance.
#include <gtest/gtest.h>

#include "paper/paper_rows.h"
#include "problems/paper/row_gradient_check.h"

namespace diffpd::problems::testing {
namespace {

TEST(RowGradientTest, CantileverInitialStateActivationAndForceGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeCantileverRow(RowSize::kSmall));
}

TEST(RowGradientTest, RollingSphereInitialStateAndForceGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeRollingSphereRow(RowSize::kSmall));
}

TEST(RowGradientTest, PlantLogMaterialGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakePlantRow(RowSize::kSmall));
}

TEST(RowGradientTest, BouncingBallLogMaterialGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeBouncingBallRow(RowSize::kSmall), 1);
}

TEST(RowGradientTest, BunnyRotationPositionVelocityGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeBunnyRow(RowSize::kSmall));
}

TEST(RowGradientTest, RoutingTendonGroupActivationGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeRoutingTendonRow(RowSize::kSmall));
}

TEST(RowGradientTest, TorusWindowedActivationGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeTorusRow(RowSize::kSmall), 1);
}

TEST(RowGradientTest, QuadrupedGaitAmplitudeAndFrequencyGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeQuadrupedRow(RowSize::kSmall), 1);
}

TEST(RowGradientTest, CowGaitAmplitudeAndFrequencyGradientMatchesCentralDifferences) {
  ExpectRowGradientMatchesCentralDifferences(MakeCowRow(RowSize::kSmall), 1);
}

}  // namespace
}  // namespace diffpd::problems::testing
