// The torus locomotion problem (problems/control/locomotion.h), small instance.
#include "problems/control/locomotion_test.h"

namespace diffpd::problems::testing {
namespace {

TEST(IpoptLocomotionTorusTest, DerivativeCheckerReportsNoError) {
  ExpectDerivativeCheckerPasses(Locomotion::Body::kTorus, 5);
}

TEST(IpoptLocomotionTorusTest, FewIterationsMoveItForwardWithinBoundsAndUpright) {
  ExpectForwardProgress(Locomotion::Body::kTorus, 12, 3);
}

}  // namespace
}  // namespace diffpd::problems::testing
