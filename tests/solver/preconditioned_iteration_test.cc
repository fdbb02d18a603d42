// The A-preconditioned iterations for H Z = B, on small dense systems where
// the answer is known: each method converges to the direct solution; CG and
// L-BFGS with exact steps take the same number of iterations (they produce
// the same iterates); each failure mode is reported per column.
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "solver/preconditioned_iteration.h"

namespace diffpd::internal {
namespace {

constexpr int kSize = 60;

// A random SPD matrix with eigenvalues in [1, condition].
MatrixXd RandomSpd(int seed, double condition) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  const MatrixXd g = MatrixXd::NullaryExpr(kSize, kSize, [&] { return normal(rng); });
  const Eigen::HouseholderQR<MatrixXd> qr(g);
  const MatrixXd q = qr.householderQ();
  VectorXd eig(kSize);
  for (int i = 0; i < kSize; ++i) eig(i) = std::pow(condition, double(i) / (kSize - 1));
  return q * eig.asDiagonal() * q.transpose();
}

MatrixXd RandomColumns(int seed, int cols) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  return MatrixXd::NullaryExpr(kSize, cols, [&] { return normal(rng); });
}

struct System {
  MatrixXd h;
  Eigen::LLT<MatrixXd> a;  // the preconditioner's factor
  std::function<VectorXd(const VectorXd&)> apply() const {
    return [this](const VectorXd& v) { return VectorXd(h * v); };
  }
  std::function<MatrixXd(const MatrixXd&)> precondition(int* calls) const {
    return [this, calls](const MatrixXd& r) {
      ++*calls;
      return MatrixXd(a.solve(r));
    };
  }
};

// H and a preconditioner A = H + a small SPD perturbation (close, as the PD
// matrix is to the Hessian near rest).
System NearbySystem() {
  System s;
  s.h = RandomSpd(1, 1e4);
  s.a.compute(s.h + 0.05 * RandomSpd(2, 10));
  return s;
}

PreconditionedSolveOptions Options(PdBackwardMethod method) {
  PreconditionedSolveOptions o;
  o.method = method;
  o.rel_tolerance = 1e-11;
  o.max_iterations = 500;
  return o;
}

TEST(PreconditionedIterationTest, EveryMethodConvergesToTheDirectSolutionForEveryColumn) {
  const System s = NearbySystem();
  const MatrixXd b = RandomColumns(3, 3);
  const MatrixXd exact = s.h.llt().solve(b);
  for (PdBackwardMethod m :
       {PdBackwardMethod::kFixedPoint, PdBackwardMethod::kLbfgs, PdBackwardMethod::kConjugateGradient}) {
    MatrixXd z;
    std::vector<char> ok;
    int iterations = 0, calls = 0;
    SolvePreconditioned(Options(m), b, s.apply(), s.precondition(&calls), &z, &ok, &iterations);
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(ok[c]) << "method " << int(m) << " column " << c;
      EXPECT_LT((z.col(c) - exact.col(c)).norm() / exact.col(c).norm(), 1e-8) << "method " << int(m);
      EXPECT_LE((b.col(c) - s.h * z.col(c)).norm(), 10 * 1e-11 * b.col(c).norm());
    }
    // One batched preconditioner call per lockstep iteration, counted per column.
    EXPECT_GE(iterations, calls);
    EXPECT_LE(iterations, 3 * calls);
  }
}

TEST(PreconditionedIterationTest, ConjugateGradientTakesTheIterationsOfLbfgsWithExactSteps) {
  // A poorer preconditioner (cond(A^-1 H) up to ~100), so that both need
  // many iterations.
  System s;
  s.h = RandomSpd(4, 1e4);
  s.a.compute(s.h + RandomSpd(5, 1e2));
  const MatrixXd b = RandomColumns(6, 1);
  PreconditionedSolveOptions o = Options(PdBackwardMethod::kLbfgs);
  o.rel_tolerance = 1e-8;
  o.lbfgs_history = 20;  // the default
  MatrixXd z_lbfgs, z_cg;
  std::vector<char> ok;
  int it_lbfgs = 0, it_cg = 0, calls = 0;
  SolvePreconditioned(o, b, s.apply(), s.precondition(&calls), &z_lbfgs, &ok, &it_lbfgs);
  ASSERT_TRUE(ok[0]);
  o.method = PdBackwardMethod::kConjugateGradient;
  SolvePreconditioned(o, b, s.apply(), s.precondition(&calls), &z_cg, &ok, &it_cg);
  ASSERT_TRUE(ok[0]);
  EXPECT_GT(it_cg, 20);
  EXPECT_LE(std::abs(it_cg - it_lbfgs), 1) << "cg " << it_cg << " lbfgs " << it_lbfgs;
  EXPECT_LT((z_cg - z_lbfgs).norm() / z_cg.norm(), 1e-6);
}

TEST(PreconditionedIterationTest, CurvatureMethodsFailOnAnIndefiniteMatrix) {
  System s = NearbySystem();
  // One negative eigenvalue, along a direction b excites.
  const VectorXd u = RandomColumns(7, 1).col(0).normalized();
  s.h -= 2.0 * (u.transpose() * s.h * u)(0) * u * u.transpose();
  const MatrixXd b = RandomColumns(8, 1);
  for (PdBackwardMethod m : {PdBackwardMethod::kLbfgs, PdBackwardMethod::kConjugateGradient}) {
    MatrixXd z;
    std::vector<char> ok;
    int iterations = 0, calls = 0;
    SolvePreconditioned(Options(m), b, s.apply(), s.precondition(&calls), &z, &ok, &iterations);
    EXPECT_FALSE(ok[0]) << "method " << int(m);
    EXPECT_LT(iterations, 500) << "negative curvature must stop the iteration, not the iteration limit";
  }
}

TEST(PreconditionedIterationTest, FixedPointFailsOnGrowthWhenAUnderestimatesH) {
  // A = H / 3: z_{k+1} = z_k + 3 H^{-1} r_k overshoots by 3x, the error grows as 2^k.
  System s;
  s.h = RandomSpd(9, 1e2);
  s.a.compute(s.h / 3.0);
  const MatrixXd b = RandomColumns(10, 2);
  MatrixXd z;
  std::vector<char> ok;
  int iterations = 0, calls = 0;
  SolvePreconditioned(Options(PdBackwardMethod::kFixedPoint), b, s.apply(), s.precondition(&calls), &z, &ok,
                      &iterations);
  EXPECT_FALSE(ok[0]);
  EXPECT_FALSE(ok[1]);
  EXPECT_LT(iterations, 2 * 10) << "growth by 10x is detected within a few iterations";
  EXPECT_EQ(z.norm(), 0.0) << "failed columns are returned as zero";
}

TEST(PreconditionedIterationTest, AZeroColumnConvergesAtOnceAndCostsNoSolve) {
  const System s = NearbySystem();
  MatrixXd b = RandomColumns(11, 2);
  b.col(0).setZero();
  MatrixXd z;
  std::vector<char> ok;
  int iterations = 0, calls = 0;
  SolvePreconditioned(Options(PdBackwardMethod::kConjugateGradient), b, s.apply(), s.precondition(&calls), &z, &ok,
                      &iterations);
  EXPECT_TRUE(ok[0]);
  EXPECT_TRUE(ok[1]);
  EXPECT_EQ(z.col(0).norm(), 0.0);
  EXPECT_EQ(iterations, calls) << "only the nonzero column is iterated";
}

TEST(PreconditionedIterationTest, TheIterationLimitLeavesAColumnUnconverged) {
  const System s = NearbySystem();
  const MatrixXd b = RandomColumns(12, 1);
  PreconditionedSolveOptions o = Options(PdBackwardMethod::kConjugateGradient);
  o.max_iterations = 2;
  MatrixXd z;
  std::vector<char> ok;
  int iterations = 0, calls = 0;
  SolvePreconditioned(o, b, s.apply(), s.precondition(&calls), &z, &ok, &iterations);
  EXPECT_FALSE(ok[0]);
  EXPECT_EQ(iterations, 2);
}

}  // namespace
}  // namespace diffpd::internal
