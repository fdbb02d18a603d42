// The cow locomotion problem (problems/control/locomotion.h), small instance.
#include "problems/control/locomotion_test.h"

namespace diffpd::problems::testing {
namespace {

TEST(IpoptLocomotionCowTest, DerivativeCheckerReportsNoError) {
  ExpectDerivativeCheckerPasses(Locomotion::Body::kCow, 6);
}

TEST(IpoptLocomotionCowTest, FewIterationsMoveItForwardWithinBoundsAndUpright) {
  ExpectForwardProgress(Locomotion::Body::kCow, 10, 3);
}

}  // namespace
}  // namespace diffpd::problems::testing
