// ceres::GradientChecker on RolloutCostFunction over every parameter block's
// case (the shared cases of solvers/core/parameter_block_cases.h): every row
// of the case as residuals, every block as a Ceres parameter block, at the
// case's point.
#include <gtest/gtest.h>

#include <ceres/gradient_checker.h>

#include "diffpd/solvers/ceres/rollout_cost_function.h"
#include "solvers/core/parameter_block_cases.h"

namespace diffpd::testing {
namespace {

class GradientCheckerTest : public ::testing::TestWithParam<std::string> {};

TEST_P(GradientCheckerTest, AcceptsTheCostFunctionOfEveryRow) {
  ParameterBlockCase c = MakeParameterBlockCase(GetParam());
  solvers::RolloutFunction& f = *c.function;
  const solvers::RolloutCostFunction cost(&f, f.AllRows());
  ceres::NumericDiffOptions numeric;
  numeric.relative_step_size = 1e-4;
  // Ridders starts at 32 steps of max(this * |x|, this): small, so that no
  // probe leaves a block's domain (nu < 0.5, drag coefficients >= 0).
  numeric.ridders_relative_initial_step_size = 1e-4;
  const std::vector<const ceres::Manifold*> no_manifolds(f.num_blocks(), nullptr);
  ceres::GradientChecker checker(&cost, &no_manifolds, numeric);
  std::vector<double*> blocks;
  VectorXd point = c.point;
  for (int b = 0; b < f.num_blocks(); ++b) blocks.push_back(point.data() + f.block_offset(b));
  ceres::GradientChecker::ProbeResults results;
  const double precision = 1e-6;
  EXPECT_TRUE(checker.Probe(blocks.data(), precision, &results))
      << results.error_log << "\nlast error: " << f.statistics().last_error;
  EXPECT_LT(results.maximum_relative_error, precision);
  EXPECT_TRUE(results.return_value);
}

INSTANTIATE_TEST_SUITE_P(Blocks, GradientCheckerTest, ::testing::ValuesIn(ParameterBlockCaseNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace diffpd::testing
