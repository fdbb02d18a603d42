// Every parameter block's derivatives (parameter_block_cases.h), checked once
// against central differences of the rollout function's values: the
// reverse-mode pull-back, the forward-mode push-forward, weighted-row
// gradients and the declared Jacobian sparsity (derivative_check.h).
#include <gtest/gtest.h>

#include "solvers/core/derivative_check.h"
#include "solvers/core/parameter_block_cases.h"

namespace diffpd::testing {
namespace {

class ParameterBlockDerivativeTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ParameterBlockDerivativeTest, PullBackAndPushForwardMatchCentralDifferences) {
  ParameterBlockCase c = MakeParameterBlockCase(GetParam());
  // Forward mode covers every block (and the state-force terms of the scenes).
  EXPECT_TRUE(c.function->ForwardModeAvailable());
  ExpectDerivativesMatchCentralDifferences(c.function.get(), c.point, 1e-3 * c.typical, 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Blocks, ParameterBlockDerivativeTest, ::testing::ValuesIn(ParameterBlockCaseNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace diffpd::testing
