// LbfgsPairs (solver/lbfgs_pairs.h): the curvature pairs and two-loop
// recursion of PD-LBFGS and of the adjoint's L-BFGS.
//
// Properties: the recursion's H satisfies the secant equation of the newest
// pair, H y = s; with H0 = I and pairs from a quadratic with Hessian B taken
// along n independent steps, H = B^-1 (n pairs recover the inverse); a full
// ring drops its oldest pair (same result as a history holding only the
// newest ones); an empty history leaves the vector as it is.
#include <gtest/gtest.h>

#include <vector>

#include "solver/lbfgs_pairs.h"

namespace diffpd::internal {
namespace {

VectorXd Apply(const LbfgsPairs& pairs, const VectorXd& g) {
  VectorXd q = g;
  std::vector<double> alpha;
  pairs.FirstLoop(&q, &alpha);  // H0 = I
  pairs.SecondLoop(alpha, &q);
  return q;
}

MatrixXd SpdMatrix(int n) {
  const MatrixXd r = MatrixXd::Random(n, n);
  return r * r.transpose() + n * MatrixXd::Identity(n, n);
}

TEST(LbfgsPairsTest, SatisfiesTheNewestSecantEquation) {
  const int n = 12;
  const MatrixXd b = SpdMatrix(n);
  LbfgsPairs pairs(5, n);
  for (int k = 0; k < 4; ++k) {
    const VectorXd s = VectorXd::Random(n), y = b * s;
    pairs.Push(s, y, 1.0 / s.dot(y));
    EXPECT_LT((Apply(pairs, y) - s).norm(), 1e-12 * s.norm()) << k + 1 << " pairs";
  }
}

TEST(LbfgsPairsTest, NConjugatePairsRecoverTheInverseHessian) {
  const int n = 6;
  const MatrixXd b = SpdMatrix(n);
  // B-conjugate steps (Gram-Schmidt in the B inner product): BFGS with exact
  // conjugate steps reproduces B^-1 after n of them.
  std::vector<VectorXd> steps;
  for (int k = 0; k < n; ++k) {
    VectorXd s = VectorXd::Random(n);
    for (const VectorXd& p : steps) s -= (p.dot(b * s) / p.dot(b * p)) * p;
    steps.push_back(s);
  }
  LbfgsPairs pairs(n, n);
  for (const VectorXd& s : steps) pairs.Push(s, b * s, 1.0 / s.dot(b * s));
  const VectorXd g = VectorXd::Random(n);
  const VectorXd exact = b.ldlt().solve(g);
  EXPECT_LT((Apply(pairs, g) - exact).norm(), 1e-10 * exact.norm());
}

TEST(LbfgsPairsTest, AFullRingDropsTheOldestPair) {
  const int n = 10, capacity = 3;
  const MatrixXd b = SpdMatrix(n);
  std::vector<VectorXd> s, y;
  for (int k = 0; k < 5; ++k) {
    s.push_back(VectorXd::Random(n));
    y.push_back(b * s.back());
  }
  LbfgsPairs ring(capacity, n), newest(capacity, n);
  for (int k = 0; k < 5; ++k) ring.Push(s[k], y[k], 1.0 / s[k].dot(y[k]));
  for (int k = 2; k < 5; ++k) newest.Push(s[k], y[k], 1.0 / s[k].dot(y[k]));
  EXPECT_EQ(ring.size(), capacity);
  const VectorXd g = VectorXd::Random(n);
  EXPECT_EQ((Apply(ring, g) - Apply(newest, g)).norm(), 0.0);
  ring.Clear();
  EXPECT_EQ(ring.size(), 0);
  EXPECT_EQ((Apply(ring, g) - g).norm(), 0.0);
}

}  // namespace
}  // namespace diffpd::internal
