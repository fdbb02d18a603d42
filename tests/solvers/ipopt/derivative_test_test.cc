// Ipopt's derivative checker (derivative_test = first-order) on a RolloutNlp
// over every parameter block's case (the shared cases of
// solvers/core/parameter_block_cases.h): every row of the case in the
// objective and as a constraint, every block as variables, at the case's
// point.
#include <gtest/gtest.h>

#include "diffpd/solvers/ipopt/ipopt_solve.h"
#include "solvers/core/parameter_block_cases.h"

namespace diffpd::testing {
namespace {

class DerivativeTestTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DerivativeTestTest, IpoptsDerivativeCheckerFindsNoError) {
  ParameterBlockCase c = MakeParameterBlockCase(GetParam());
  const std::vector<int> rows = c.function->AllRows();
  Ipopt::SmartPtr<solvers::RolloutNlp> nlp = new solvers::RolloutNlp(std::move(c.function));
  nlp->AddObjectiveRows(rows, 1.0);
  nlp->AddConstraintRows(rows, -1e3, 1e3);
  nlp->SetStartingPoint(c.point);
  solvers::IpoptOptions o;
  o.string_options = {{"derivative_test", "first-order"}};
  o.int_options = {{"max_iter", 0}};
  // Check at the starting point itself (Ipopt's default moves it randomly by
  // up to 10 units, far outside where the cases are meant to live).
  o.num_options = {{"derivative_test_perturbation", 1e-6}, {"point_perturbation_radius", 0.0}};
  const solvers::IpoptSummary s = SolveWithIpopt(nlp, o);
  EXPECT_NE(s.log.find("Starting derivative checker for first derivatives."), std::string::npos) << s.log;
  EXPECT_EQ(s.derivative_checker_errors, 0) << s.log;
}

INSTANTIATE_TEST_SUITE_P(Blocks, DerivativeTestTest, ::testing::ValuesIn(ParameterBlockCaseNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace
}  // namespace diffpd::testing
