// The starfish's controller trained over several initial states
// (swimmer_starts.h) on 2 MPI ranks (CTest runs it under mpiexec -n 2): the
// same training code over a DistributedRolloutSet gives the learning curve,
// the per-start rewards and the final weights of the training over a
// LocalRolloutSet of the same starts, bit for bit, with Adam, L-BFGS and
// Ipopt.
#include <gtest/gtest.h>
#include <mpi.h>

#include "control/starfish_control.h"
#include "control/swimmer_starts.h"
#include "diffpd/solvers/mpi/distributed_rollout_set.h"

namespace diffpd::problems {
namespace {

constexpr int kSteps = 10;
constexpr int kStarts = 3;  // 2 on rank 0, 1 on rank 1

class DistributedSwimmerTrainingTest : public ::testing::TestWithParam<ControlOptimizer> {};

TEST_P(DistributedSwimmerTrainingTest, EqualsTheLocalTrainingBitForBit) {
  if (!ControlOptimizerAvailable(GetParam())) GTEST_SKIP() << "the optimiser's adapter is not built";
  Swimmer swimmer = StarfishControl().MakeSwimmer(true);
  swimmer.steps = kSteps;
  SolverOptions options = StarfishControl().BaseOptions(true);
  options.num_threads = 1;
  options.adjoint_solver = AdjointSolver::kIterative;
  SwimmerStartsOptions starts;
  starts.count = kStarts;
  const auto make = [&](int i) { return SwimmerStartTerm(swimmer, options, 42, i, starts); };
  solvers::DistributedRolloutSet distributed(MPI_COMM_WORLD, kStarts, solvers::TermObjective::kSum, make);
  if (!distributed.is_root()) {
    distributed.Serve();
    return;
  }
  TrainingSettings settings;
  settings.evaluations = 2;
  settings.optimizer = GetParam();
  std::vector<solvers::RolloutTerm> terms;
  for (int i = 0; i < kStarts; ++i) terms.push_back(make(i));
  solvers::LocalRolloutSet local(std::move(terms), solvers::TermObjective::kSum);
  const MultiStartTraining a = TrainOverStarts(&local, kSteps, settings);
  const MultiStartTraining b = TrainOverStarts(&distributed, kSteps, settings);
  distributed.Stop();
  EXPECT_EQ(b.final_parameters, a.final_parameters);
  EXPECT_EQ(b.initial_start_rewards, a.initial_start_rewards);
  EXPECT_EQ(b.final_start_rewards, a.final_start_rewards);
  ASSERT_EQ(b.history.size(), a.history.size());
  for (size_t e = 0; e < a.history.size(); ++e) {
    EXPECT_EQ(b.history[e].reward, a.history[e].reward) << "evaluation " << e;
    EXPECT_EQ(b.history[e].gradient_norm, a.history[e].gradient_norm) << "evaluation " << e;
    EXPECT_EQ(b.history[e].simulated_steps, a.history[e].simulated_steps) << "evaluation " << e;
  }
  EXPECT_GT((b.final_parameters - b.initial_parameters).norm(), 0.0);
}

INSTANTIATE_TEST_SUITE_P(Optimizers, DistributedSwimmerTrainingTest,
                         ::testing::Values(ControlOptimizer::kAdam, ControlOptimizer::kLbfgs, ControlOptimizer::kIpopt),
                         [](const ::testing::TestParamInfo<ControlOptimizer>& info) { return ToString(info.param); });

}  // namespace
}  // namespace diffpd::problems

// Every rank runs every test (the sets are collective); only rank 0 prints.
// The exit status is non-zero if any rank failed.
int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank != 0) {
    ::testing::TestEventListeners& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int failed = RUN_ALL_TESTS() != 0 ? 1 : 0, any = 0;
  MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return any;
}
