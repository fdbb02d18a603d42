// DistributedRolloutSet (distributed_rollout_set.h), run on 2 ranks by CTest
// (mpiexec -n 2): rows, Jacobians, values and gradients equal a
// LocalRolloutSet's over the same terms bit for bit, with terms spread
// unevenly; a term failing on another rank is reported on rank 0 with its
// reason; construction errors are thrown alike on every rank; evaluations
// off rank 0 are refused.
#include <gtest/gtest.h>
#include <mpi.h>

#include "diffpd/error.h"
#include "diffpd/solvers/mpi/distributed_rollout_set.h"
#include "solvers/core/rollout_set_terms.h"
#include "util/expect_message.h"

namespace diffpd::testing {
namespace {

using namespace solvers;

int Rank() {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

int Size() {
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

TEST(DistributedRolloutSetTest, EqualsTheLocalSetBitForBit) {
  constexpr int kTerms = 5;  // 3 on rank 0, 2 on rank 1
  for (TermObjective objective : {TermObjective::kLeastSquares, TermObjective::kSum}) {
    DistributedRolloutSet set(MPI_COMM_WORLD, kTerms, objective, [](int t) { return BeamTerm(t); });
    EXPECT_EQ(set.num_terms(), kTerms);
    EXPECT_EQ(set.num_rows(), 2 + 3 + 4 + 2 + 3);
    EXPECT_EQ(set.num_parameters(), 2);
    if (!set.is_root()) {
      set.Serve();
      continue;
    }
    std::vector<RolloutTerm> terms;
    for (int t = 0; t < kTerms; ++t) terms.push_back(BeamTerm(t));
    LocalRolloutSet local(std::move(terms), objective);
    VectorXd p = set.initial_parameters();
    p(0) *= 1.3;
    VectorXd v, v_local, g, g_local;
    MatrixXd j, j_local;
    double l = 0, l_local = 0;
    ASSERT_TRUE(set.Evaluate(p, &v, &j)) << set.last_error();
    ASSERT_TRUE(local.Evaluate(p, &v_local, &j_local)) << local.last_error();
    EXPECT_EQ(v, v_local);
    EXPECT_EQ(j, j_local);
    ASSERT_TRUE(set.Evaluate(p, &v, nullptr));
    EXPECT_EQ(v, v_local);
    ASSERT_TRUE(set.Gradient(p, &g, &l)) << set.last_error();
    ASSERT_TRUE(local.Gradient(p, &g_local, &l_local));
    EXPECT_EQ(g, g_local);
    EXPECT_EQ(l, l_local);
    EXPECT_FALSE(set.Evaluate(VectorXd::Ones(3), &v, nullptr));
    EXPECT_EQ(set.last_error(), "DistributedRolloutSet: p has 3 entries, expected 2");
    // Rank 0 simulated its own terms only: 3 of 5, at one point.
    EXPECT_EQ(set.statistics().rollouts, Size() == 1 ? 5 : 3);
    set.Stop();
    EXPECT_FALSE(set.Gradient(p, &g, nullptr));
    EXPECT_EQ(set.last_error(), "DistributedRolloutSet: Gradient after Stop");
  }
}

TEST(DistributedRolloutSetTest, FailureOnAnotherRankReachesRankZeroWithItsReason) {
  // Term 3 (rank 1 of 2) cannot converge in one iteration.
  DistributedRolloutSet set(MPI_COMM_WORLD, 4, TermObjective::kLeastSquares,
                            [](int t) { return BeamTerm(t, t == 3 ? 1 : 20000); });
  if (!set.is_root()) {
    set.Serve();
    return;
  }
  VectorXd v, g;
  EXPECT_FALSE(set.Evaluate(set.initial_parameters(), &v, nullptr));
  EXPECT_EQ(set.last_error().rfind("term 3: rollout failed (", 0), 0u) << set.last_error();
  EXPECT_FALSE(set.Gradient(set.initial_parameters(), &g, nullptr));
  EXPECT_EQ(set.last_error().rfind("term 3: rollout failed (", 0), 0u) << set.last_error();
  set.Stop();
}

TEST(DistributedRolloutSetTest, ConstructionErrorsAreThrownOnEveryRank) {
  const auto throwing = [](int t) -> RolloutTerm {
    if (t == 1) throw InvalidInputError("no recording for this term");
    return BeamTerm(t);
  };
  const std::string owner = std::to_string(1 % Size());
  EXPECT_THROW_MESSAGE(DistributedRolloutSet(MPI_COMM_WORLD, 3, TermObjective::kSum, throwing), InvalidInputError,
                       "DistributedRolloutSet: term 1 (rank " + owner + "): no recording for this term");
  const auto mismatched = [](int t) {
    RolloutTerm term = BeamTerm(t);
    if (t == 1)
      term.function->AddBlock(std::make_unique<MaterialBlock>(
          std::vector<MaterialBlock::Entry>{MaterialField::kDensity}, term.function->scene()));
    return term;
  };
  EXPECT_THROW_MESSAGE(DistributedRolloutSet(MPI_COMM_WORLD, 2, TermObjective::kSum, mismatched), InvalidInputError,
                       "DistributedRolloutSet: term 1 has 3 parameters, term 0 has 2");
  EXPECT_THROW_MESSAGE(DistributedRolloutSet(MPI_COMM_WORLD, 0, TermObjective::kSum, throwing), InvalidInputError,
                       "DistributedRolloutSet: num_terms = 0 is invalid: must be >= 1");
}

TEST(DistributedRolloutSetTest, OnlyRankZeroEvaluates) {
  DistributedRolloutSet set(MPI_COMM_WORLD, 2, TermObjective::kSum, [](int t) { return BeamTerm(t); });
  if (set.is_root()) {
    EXPECT_THROW_MESSAGE(set.Serve(), InvalidInputError,
                         "DistributedRolloutSet: Serve is called on rank 0, which evaluates");
    set.Stop();
    return;
  }
  VectorXd v;
  EXPECT_FALSE(set.Evaluate(VectorXd::Ones(2), &v, nullptr));
  EXPECT_EQ(set.last_error(), "DistributedRolloutSet: Evaluate is called on rank " + std::to_string(Rank()) +
                                  "; only rank 0 evaluates (the others Serve)");
  set.Serve();
}

}  // namespace
}  // namespace diffpd::testing

// Every rank runs every test (the sets are collective); only rank 0 prints.
// The exit status is non-zero if any rank failed.
int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  if (diffpd::testing::Rank() != 0) {
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int failed = RUN_ALL_TESTS() != 0 ? 1 : 0, any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return any;
}
