// The cow locomotion problem (problems/locomotion.h), small instance.
#include "ipopt_locomotion_test.h"

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
