// The PD factor's copy for parallel solves and its memory-lean alternative
// (SolverOptions::pd_factor_copy_max_bytes): without the copy CHOLMOD solves
// and the steps, gradients and tangents agree with the copy's to rounding.
#include <gtest/gtest.h>

#include <random>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "solver/cholmod_solver.h"
#include "solver/grid_matrices.h"
#include "solver/parallel_triangular_solve.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

using internal::CholmodLayout;
using internal::CholmodOrdering;
using internal::CholmodSolveKernel;

double RelativeDifference(const VectorXd& a, const VectorXd& b) { return (a - b).norm() / b.norm(); }

TEST(FactorCopyTest, LeanPathSkipsTheCopyAndGivesTheSameStepsAndGradients) {
  const Scene scene = testing::SmallBeamScene();
  for (Method method : {Method::kPd, Method::kPdLbfgs}) {
    SolverOptions options = testing::TightOptions(method);
    options.num_threads = 2;
    Simulator copied(scene, options);
    options.pd_factor_copy_max_bytes = 0;  // never a copy
    Simulator lean(scene, options);
    EXPECT_EQ(copied.pd_factor_copy_bytes(), 0u);  // no PD step yet
    const State start = testing::MovingStart(copied);
    const std::vector<StepInput> inputs(4);
    const Rollout a = copied.Simulate(start, inputs);
    const Rollout b = lean.Simulate(start, inputs);
    EXPECT_GT(copied.pd_factor_copy_bytes(), 0u) << ToString(method);
    EXPECT_EQ(lean.pd_factor_copy_bytes(), 0u) << ToString(method);
    for (int k = 1; k <= 4; ++k)
      EXPECT_LT(RelativeDifference(b.states[k].x, a.states[k].x), 1e-12) << ToString(method) << " state " << k;
    LossGradient loss(4);
    std::mt19937_64 rng(3);
    loss.dx[4] = testing::RandomVector(copied.num_dofs(), &rng, 1.0);
    const RolloutGradient ga = copied.Backward(a, loss);
    const RolloutGradient gb = lean.Backward(b, loss);
    EXPECT_LT(RelativeDifference(gb.x0, ga.x0), 1e-9) << ToString(method);
    EXPECT_NEAR(gb.youngs_modulus, ga.youngs_modulus, 1e-9 * std::abs(ga.youngs_modulus)) << ToString(method);
  }
}

// The estimate made before the copy is an upper bound of its size, and a
// limit below the estimate leaves the solver without a copy, solving alike.
TEST(FactorCopyTest, EstimateBoundsTheCopyAndALimitBelowItLeavesNoCopy) {
  const SparseMatrix a = internal::HexGridMatrix(12, 10, 8, 1.0);
  for (CholmodLayout layout : {CholmodLayout::kSimplicial, CholmodLayout::kSupernodal}) {
    internal::CholmodSolver copied(layout, CholmodOrdering::kNestedDissection, CholmodSolveKernel::kParallelCopy);
    copied.set_solve_threads(2);
    ASSERT_TRUE(copied.Factorize(a));
    ASSERT_NE(copied.parallel_copy(), nullptr);
    const double estimate =
        internal::ParallelTriangularSolve::EstimatedBytes(static_cast<int>(a.rows()), copied.factor_nonzeros());
    EXPECT_GE(estimate, static_cast<double>(copied.parallel_copy()->bytes()));
    EXPECT_LE(estimate, 2.0 * static_cast<double>(copied.parallel_copy()->bytes()));
    internal::CholmodSolver lean(layout, CholmodOrdering::kNestedDissection, CholmodSolveKernel::kParallelCopy);
    lean.set_solve_threads(2);
    lean.set_copy_max_bytes(0.5 * estimate);
    ASSERT_TRUE(lean.Factorize(a));
    EXPECT_EQ(lean.parallel_copy(), nullptr);
    std::mt19937_64 rng(1);
    const MatrixXd b =
        MatrixXd::NullaryExpr(a.rows(), 3, [&rng]() { return std::uniform_real_distribution<double>(-1, 1)(rng); });
    const MatrixXd x = copied.Solve(b), y = lean.Solve(b);
    EXPECT_LT((x - y).norm() / x.norm(), 1e-13);
  }
  SolverOptions options;
  options.pd_factor_copy_max_bytes = -1;
  ASSERT_THROW_MESSAGE(options.Validate(), InvalidInputError,
                       "solver options: pd_factor_copy_max_bytes = -1 is invalid: must be >= 0 (0: never a copy, "
                       "infinity: always)");
}

}  // namespace
}  // namespace diffpd
