// LocalRolloutSet (rollout_set.h): the terms' rows stacked in term order,
// the scalar objective's value and gradient (least squares and sum) exact
// against central differences, failures naming the term, and the
// validation of its terms.
#include <gtest/gtest.h>

#include "diffpd/error.h"
#include "solvers/core/rollout_set_terms.h"
#include "util/central_difference.h"
#include "util/expect_message.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

std::vector<RolloutTerm> BeamTerms(int count) {
  std::vector<RolloutTerm> terms;
  for (int t = 0; t < count; ++t) terms.push_back(BeamTerm(t));
  return terms;
}

TEST(RolloutSetTest, ValuesAndJacobianStackTheTermsInOrder) {
  LocalRolloutSet set(BeamTerms(3), TermObjective::kLeastSquares);
  ASSERT_EQ(set.num_parameters(), 2);
  ASSERT_EQ(set.num_rows(), 2 + 3 + 4);
  const VectorXd p = set.initial_parameters();
  VectorXd v;
  MatrixXd j;
  ASSERT_TRUE(set.Evaluate(p, &v, &j)) << set.last_error();
  for (int t = 0, row = 0; t < 3; ++t) {
    RolloutTerm alone = BeamTerm(t);
    VectorXd vt;
    MatrixXd jt;
    ASSERT_TRUE(alone.function->Evaluate(p, alone.rows, &vt, &jt));
    EXPECT_EQ(v.segment(row, vt.size()), vt) << "term " << t;
    EXPECT_EQ(j.middleRows(row, vt.size()), jt) << "term " << t;
    row += static_cast<int>(vt.size());
  }
}

TEST(RolloutSetTest, ObjectiveGradientsMatchCentralDifferences) {
  for (TermObjective objective : {TermObjective::kLeastSquares, TermObjective::kSum}) {
    LocalRolloutSet set(BeamTerms(3), objective);
    const VectorXd p = set.initial_parameters();
    VectorXd g;
    double value = 0;
    ASSERT_TRUE(set.Gradient(p, &g, &value)) << set.last_error();
    double recomputed = 0;
    ASSERT_TRUE(set.Value(p, &recomputed));
    EXPECT_NEAR(value, recomputed, 1e-14 * std::abs(value));
    DifferenceOptions options;
    options.noise = 1e-11;  // the rollouts' tolerance
    options.input_scale = 0.5 * std::min(p(0), 0.5 - p(1));
    const DifferenceCheck c = CheckGradient(
        [&](const VectorXd& q) {
          double l = 0;
          EXPECT_TRUE(set.Value(q, &l)) << set.last_error();
          return l;
        },
        p, g, options);
    EXPECT_TRUE(Passes(c)) << (objective == TermObjective::kSum ? "sum" : "least squares");
  }
}

TEST(RolloutSetTest, FailingTermIsNamed) {
  std::vector<RolloutTerm> terms;
  terms.push_back(BeamTerm(0));
  terms.push_back(BeamTerm(1, /*max_iterations=*/1));
  LocalRolloutSet set(std::move(terms), TermObjective::kLeastSquares);
  VectorXd v, g;
  EXPECT_FALSE(set.Evaluate(set.initial_parameters(), &v, nullptr));
  EXPECT_EQ(set.last_error().rfind("term 1: rollout failed (", 0), 0u) << set.last_error();
  EXPECT_FALSE(set.Gradient(set.initial_parameters(), &g, nullptr));
  EXPECT_EQ(set.last_error().rfind("term 1: rollout failed (", 0), 0u) << set.last_error();
}

TEST(RolloutSetTest, InvalidTermsAreRejectedWithTheirReason) {
  EXPECT_THROW_MESSAGE(LocalRolloutSet({}, TermObjective::kSum), InvalidInputError, "LocalRolloutSet: no term");
  std::vector<RolloutTerm> terms = BeamTerms(1);
  terms[0].rows.push_back(7);
  EXPECT_THROW_MESSAGE(LocalRolloutSet(std::move(terms), TermObjective::kSum), InvalidInputError,
                       "rollout term: row 7 is out of range [0, 2)");
  terms = BeamTerms(2);
  terms[1].function->AddBlock(std::make_unique<MaterialBlock>(
      std::vector<MaterialBlock::Entry>{MaterialField::kDensity}, terms[1].function->scene()));
  EXPECT_THROW_MESSAGE(LocalRolloutSet(std::move(terms), TermObjective::kSum), InvalidInputError,
                       "LocalRolloutSet: term 1 has 3 parameters, term 0 has 2");
}

}  // namespace
}  // namespace diffpd::testing
