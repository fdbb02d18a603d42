// The memory bound on the PD methods' direct adjoint
// (SolverOptions::adjoint_direct_max_bytes): its estimate of the step
// Hessian's factor, kAuto keeping to the iteration above the bound with the
// same gradient, and a failed iteration under the bound raising a clear
// error instead of a factorisation.
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <string>

#include "diffpd/error.h"
#include "diffpd/simulator.h"
#include "solver/cholmod_solver.h"
#include "solver/grid_matrices.h"
#include "test_scenes.h"
#include "util/expect_message.h"

namespace diffpd {
namespace {

using internal::CholmodLayout;
using internal::CholmodOrdering;

// H couples every pair of nodes that A couples with a dense 3 x 3 block:
// the pattern of A (x) B for an SPD 3 x 3 B. The estimate, 9 times the
// entries of A's factor, must stay within 2x of the entries of H's factor
// under the orderings each gets (A: nested dissection, as the PD system;
// H: CHOLMOD's default, as the direct adjoint).
TEST(AdjointMemoryBoundTest, NineTimesThePdFactorEstimatesTheHessianFactor) {
  for (const auto& cells : {std::array<int, 3>{12, 10, 8}, std::array<int, 3>{24, 6, 6}}) {
    const SparseMatrix a = internal::HexGridMatrix(cells[0], cells[1], cells[2], 1.0);
    Eigen::Matrix3d b;
    b << 2, 0.5, 0.5, 0.5, 2, 0.5, 0.5, 0.5, 2;
    std::vector<Eigen::Triplet<double>> entries;
    for (int k = 0; k < a.outerSize(); ++k)
      for (SparseMatrix::InnerIterator it(a, k); it; ++it)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            entries.emplace_back(3 * static_cast<int>(it.row()) + i, 3 * static_cast<int>(it.col()) + j,
                                 it.value() * b(i, j));
    SparseMatrix h(3 * a.rows(), 3 * a.cols());
    h.setFromTriplets(entries.begin(), entries.end());
    internal::CholmodSolver pd(CholmodLayout::kSupernodal, CholmodOrdering::kNestedDissection);
    internal::CholmodSolver direct(CholmodLayout::kSupernodal, CholmodOrdering::kAutomatic);
    ASSERT_TRUE(pd.Factorize(a));
    ASSERT_TRUE(direct.Factorize(h));
    const double ratio = 9 * pd.factor_nonzeros() / direct.factor_nonzeros();
    EXPECT_GT(ratio, 0.5) << cells[0] << "x" << cells[1] << "x" << cells[2];
    EXPECT_LT(ratio, 2.0) << cells[0] << "x" << cells[1] << "x" << cells[2];
  }
}

RolloutGradient Gradient(const Scene& scene, const SolverOptions& options, int steps) {
  Simulator sim(scene, options);
  const Rollout r = sim.Simulate(testing::MovingStart(sim), std::vector<StepInput>(steps));
  LossGradient loss(steps);
  std::mt19937_64 rng(5);
  loss.dx[steps] = testing::RandomVector(sim.num_dofs(), &rng, 1.0);
  return sim.Backward(r, loss);
}

TEST(AdjointMemoryBoundTest, AutoKeepsToTheIterationAboveTheBoundWithTheSameGradient) {
  const Scene scene = testing::SmallBeamScene();
  for (Method method : {Method::kPd, Method::kPdLbfgs}) {
    SolverOptions options = testing::TightOptions(method);
    options.adjoint_solver = AdjointSolver::kAuto;
    // The tight adjoint tolerance needs many iterations: over 20 steps kAuto
    // factorises after its first.
    const RolloutGradient unbounded = Gradient(scene, options, 20);
    EXPECT_GT(unbounded.report.direct_steps, 0) << ToString(method);
    options.adjoint_direct_max_bytes = 0;
    const RolloutGradient bounded = Gradient(scene, options, 20);
    EXPECT_EQ(bounded.report.direct_steps, 0) << ToString(method);
    EXPECT_EQ(bounded.report.iterative_steps, 20) << ToString(method);
    EXPECT_LT((bounded.x0 - unbounded.x0).norm() / unbounded.x0.norm(), 1e-7) << ToString(method);
    // kDirect is honoured whatever the bound.
    options.adjoint_solver = AdjointSolver::kDirect;
    EXPECT_EQ(Gradient(scene, options, 6).report.direct_steps, 6) << ToString(method);
  }
}

TEST(AdjointMemoryBoundTest, AFailedIterationUnderTheBoundRaisesInsteadOfFactorising) {
  const Scene scene = testing::SmallBeamScene();
  SolverOptions options = testing::TightOptions(Method::kPd);
  options.pd_backward = PdBackwardMethod::kFixedPoint;
  options.adjoint_solver = AdjointSolver::kIterative;
  options.backward_max_iterations = 1;
  options.adjoint_direct_max_bytes = 0;
  const std::string message = testing::MessageOf<SolverError>([&] { Gradient(scene, options, 2); });
  const std::string head =
      "pd backward: the iterative solve did not converge in 1 iterations, and no direct solve falls back: its "
      "factor of the step Hessian (about ";
  const std::string tail = " GiB) exceeds SolverOptions::adjoint_direct_max_bytes (0 GiB)";
  EXPECT_NE(message.find(head), std::string::npos) << message;
  EXPECT_NE(message.find(tail), std::string::npos) << message;
  // Without the bound the same iteration falls back (solver_agreement_test).
  options.adjoint_direct_max_bytes = 8589934592.0;
  EXPECT_EQ(Gradient(scene, options, 2).report.fallbacks, 2);
}

TEST(AdjointMemoryBoundTest, RejectsANegativeBound) {
  SolverOptions options;
  options.adjoint_direct_max_bytes = -1;
  EXPECT_THROW_MESSAGE(options.Validate(), InvalidInputError,
                       "solver options: adjoint_direct_max_bytes = -1 is invalid: must be >= 0 (0: no direct PD "
                       "adjoint unless kDirect, infinity: no bound)");
}

}  // namespace
}  // namespace diffpd
