// The quadruped locomotion problem (problems/control/locomotion.h), small instance.
#include "problems/control/locomotion_test.h"

namespace diffpd::problems::testing {
namespace {

TEST(IpoptLocomotionQuadrupedTest, DerivativeCheckerReportsNoError) {
  ExpectDerivativeCheckerPasses(Locomotion::Body::kQuadruped, 8);
}

TEST(IpoptLocomotionQuadrupedTest, FewIterationsMoveItForwardWithinBoundsAndUpright) {
  ExpectForwardProgress(Locomotion::Body::kQuadruped, 30, 4);
}

}  // namespace
}  // namespace diffpd::problems::testing
