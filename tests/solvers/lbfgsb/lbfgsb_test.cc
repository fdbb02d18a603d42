// L-BFGS-B (solvers/lbfgsb): bounded problems with known solutions (a
// bounded Rosenbrock, a quadratic built around a chosen KKT point), the
// unbounded case against the L-BFGS two-loop recursion, every stopping test
// with its reason, option and problem errors with their messages, and failed
// evaluations.
#include "diffpd/solvers/lbfgsb/lbfgsb.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "diffpd/error.h"
#include "util/expect_message.h"

namespace diffpd::solvers {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

bool Rosenbrock(const VectorXd& x, double* f, VectorXd* g) {
  const int n = static_cast<int>(x.size());
  *f = 0;
  *g = VectorXd::Zero(n);
  for (int i = 0; i + 1 < n; ++i) {
    const double a = x(i + 1) - x(i) * x(i), b = 1 - x(i);
    *f += 100 * a * a + b * b;
    (*g)(i) += -400 * a * x(i) - 2 * b;
    (*g)(i + 1) += 200 * a;
  }
  return true;
}

// f = x^T A x / 2 - b^T x.
struct Quadratic {
  MatrixXd a;
  VectorXd b;
  bool operator()(const VectorXd& x, double* f, VectorXd* g) const {
    *g = a * x - b;
    *f = 0.5 * x.dot(a * x) - b.dot(x);
    return true;
  }
};

MatrixXd SpdMatrix(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  MatrixXd q(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) q(i, j) = u(rng);
  return q * q.transpose() + 0.5 * MatrixXd::Identity(n, n);
}

TEST(LbfgsbTest, BoundedRosenbrockStopsAtTheBoundWhereItsKktConditionsHold) {
  // min (1 - x)^2 + 100 (y - x^2)^2 with x <= 0.5: x = 0.5 (df/dx = -1 < 0
  // there, the bound active), y = x^2 = 0.25.
  const VectorXd lower = Eigen::Vector2d(-2, -1), upper = Eigen::Vector2d(0.5, 2);
  LbfgsbOptions o;
  o.pgtol = 1e-9;
  o.ftol = 0;
  const LbfgsbResult r = MinimizeLbfgsb(Rosenbrock, (VectorXd(2) << -1.2, 1).finished(), lower, upper, o);
  EXPECT_EQ(r.stop, LbfgsbStop::kProjectedGradient) << ToString(r.stop);
  EXPECT_EQ(r.x(0), 0.5);  // exactly at its bound
  EXPECT_NEAR(r.x(1), 0.25, 1e-9);
  EXPECT_NEAR(r.gradient(0), -1, 1e-8);
  EXPECT_LE(std::abs(r.gradient(1)), 1e-9);
  EXPECT_EQ(r.failed_evaluations, 0);
}

TEST(LbfgsbTest, BoundedQuadraticFindsItsKktPointAndItsActiveSet) {
  // The solution chosen first: x* with variables at the lower bound (-1),
  // at the upper (1) and inside, and g* = A x* - b that is 0 inside,
  // > 0 at a lower bound and < 0 at an upper one; then b = A x* - g*.
  const int n = 20;
  Quadratic q;
  q.a = SpdMatrix(n, 7);
  VectorXd x_star(n), g_star(n);
  for (int i = 0; i < n; ++i) {
    const int kind = i % 4;
    x_star(i) = kind == 0 ? -1.0 : kind == 1 ? 1.0 : 0.3 * std::sin(i);
    g_star(i) = kind == 0 ? 0.5 + 0.1 * i : kind == 1 ? -0.7 - 0.05 * i : 0.0;
  }
  q.b = q.a * x_star - g_star;
  // pgtol: f (~ -53 at x*) resolves changes down to ~1e-14, so gradients
  // to ~1e-7 only.
  LbfgsbOptions o;
  o.pgtol = 1e-6;
  o.ftol = 0;
  const LbfgsbResult r = MinimizeLbfgsb(q, VectorXd::Zero(n), VectorXd::Constant(n, -1), VectorXd::Constant(n, 1), o);
  EXPECT_EQ(r.stop, LbfgsbStop::kProjectedGradient) << ToString(r.stop);
  EXPECT_LE((r.x - x_star).lpNorm<Eigen::Infinity>(), 1e-5);
  for (int i = 0; i < n; ++i) {
    if (i % 4 < 2) {
      EXPECT_EQ(r.x(i), x_star(i)) << "variable " << i << " must sit exactly on its bound";
    }
  }
  EXPECT_LE((r.gradient - g_star).lpNorm<Eigen::Infinity>(), 1e-5);
  // The truncated subspace step of the 1995 paper reaches the same point.
  o.project_subspace_step = false;
  const LbfgsbResult t = MinimizeLbfgsb(q, VectorXd::Zero(n), VectorXd::Constant(n, -1), VectorXd::Constant(n, 1), o);
  EXPECT_EQ(t.stop, LbfgsbStop::kProjectedGradient) << ToString(t.stop);
  EXPECT_LE((t.x - x_star).lpNorm<Eigen::Infinity>(), 1e-5);
}

// sum 100 (x_i - 1)^4 + (x_i - 1)^2: the first step (to the box's corner)
// raises f 57-fold, so the line search must interpolate far back.
bool Steep(const VectorXd& x, double* f, VectorXd* g) {
  const VectorXd r = x.array() - 1;
  *f = (100 * r.array().pow(4) + r.array().square()).sum();
  *g = (400 * r.array().cube() + 2 * r.array()).matrix();
  return true;
}

// sum exp(a_i x_i) - b_i x_i, a from 1 to 3, b from 2 to 5 (n >= 2).
bool Exponentials(const VectorXd& x, double* f, VectorXd* g) {
  const int n = static_cast<int>(x.size());
  *f = 0;
  *g = VectorXd(n);
  for (int i = 0; i < n; ++i) {
    const double a = 1 + 2.0 * i / (n - 1), b = 2 + 3.0 * i / (n - 1), e = std::exp(a * x(i));
    *f += e - b * x(i);
    (*g)(i) = a * e - b;
  }
  return true;
}

// The Rosenbrock function with its gradient's entries off by a relative 1e-4
// (a deterministic function of x, as a simulation solved to a tolerance).
bool RosenbrockNoisyGradient(const VectorXd& x, double* f, VectorXd* g) {
  Rosenbrock(x, f, g);
  double s = 0;
  for (int i = 0; i < x.size(); ++i) s += x(i) * (i + 1);
  for (int i = 0; i < x.size(); ++i) (*g)(i) *= 1 + 1e-4 * std::sin(1e6 * s + 7.0 * i);
  return true;
}

TEST(LbfgsbTest, TakesScipysIterationsAndEvaluationsOnBoundedProblems) {
  // The same algorithm as scipy's (1.10.1, minimize(method='L-BFGS-B'),
  // maxcor 10, the same ftol and gtol): evaluations after each iteration,
  // recorded from scipy's callback:
  //   Steep, 5 variables in [-10, 10] from 5:            3 6 7 8 9 10 11 12 13 14 15 16
  //   Exponentials, 6 variables in [-5, 5] from 3:       2 9 12 14 15 17 18 19 ... 29
  //   Rosenbrock, 2 variables in [-2, 0.5] x [-1, 2]:    3 4 5 7 8 12 14 15 16 17 19 21 22 23 25 ... 30
  //   Rosenbrock, 10 variables, no bounds, from -1.2 (first step 1 / |d|): 2 3 ... 13 15 16 18 19 20 21 23 25 ...
  //     84 evaluations in 69 iterations
  //   Rosenbrock with a noisy gradient, 10 variables in [-2, 0.6] from -1.2: 27 iterations, 30 evaluations,
  //     x = (0.6, 0.37496961002, 0.15222888399, ...)
  // The line searches of the first iterations interpolate (More and
  // Thuente's safeguarded steps): those counts must match exactly, the
  // totals within one.
  struct Case {
    const char* name;
    LbfgsbObjective f;
    VectorXd x0, lower, upper;
    double ftol, pgtol;
    std::vector<long> evaluations;  // after the first iterations
    int iterations;
    long total;
    VectorXd solution;  // its first entries
  };
  const std::vector<Case> cases = {
      {"steep",
       Steep,
       VectorXd::Constant(5, 5),
       VectorXd::Constant(5, -10),
       VectorXd::Constant(5, 10),
       1e-12,
       1e-8,
       {3, 6, 7},
       12,
       16,
       VectorXd::Ones(5)},
      {"exponentials",
       Exponentials,
       VectorXd::Constant(6, 3),
       VectorXd::Constant(6, -5),
       VectorXd::Constant(6, 5),
       1e-12,
       1e-8,
       {2, 9, 12, 14, 15},
       18,
       29,
       (VectorXd(3) << std::log(2.0), std::log(2.6 / 1.4) / 1.4, std::log(3.2 / 1.8) / 1.8).finished()},
      {"bounded Rosenbrock",
       Rosenbrock,
       (VectorXd(2) << -1.2, 1).finished(),
       (VectorXd(2) << -2, -1).finished(),
       (VectorXd(2) << 0.5, 2).finished(),
       0,
       1e-9,
       {3, 4, 5, 7, 8, 12},
       20,
       30,
       (VectorXd(2) << 0.5, 0.25).finished()},
      {"unbounded Rosenbrock",
       Rosenbrock,
       VectorXd::Constant(10, -1.2),
       VectorXd::Constant(10, -kInf),
       VectorXd::Constant(10, kInf),
       1e-12,
       1e-8,
       {2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 15, 16, 18, 19, 20, 21, 23, 25},
       69,
       84,
       VectorXd::Ones(10)},
      {"noisy gradient",
       RosenbrockNoisyGradient,
       VectorXd::Constant(10, -1.2),
       VectorXd::Constant(10, -2),
       VectorXd::Constant(10, 0.6),
       1e-12,
       1e-8,
       {},
       27,
       30,
       (VectorXd(3) << 0.6, 0.37496961002, 0.15222888399).finished()},
  };
  for (const Case& c : cases) {
    LbfgsbOptions o;
    o.ftol = c.ftol;
    o.pgtol = c.pgtol;
    const LbfgsbResult r = MinimizeLbfgsb(c.f, c.x0, c.lower, c.upper, o);
    ASSERT_GT(r.history.size(), c.evaluations.size()) << c.name;
    for (size_t k = 0; k < c.evaluations.size(); ++k)
      EXPECT_EQ(r.history[k + 1].evaluations, c.evaluations[k]) << c.name << ", iteration " << k + 1;
    EXPECT_NEAR(r.iterations, c.iterations, 1) << c.name;
    EXPECT_NEAR(r.evaluations, c.total, 1) << c.name;
    EXPECT_LE((r.x.head(c.solution.size()) - c.solution).lpNorm<Eigen::Infinity>(), 1e-6) << c.name;
    EXPECT_EQ(r.memory_resets, 0) << c.name;
  }
}

TEST(LbfgsbTest, AFarTooLongFirstStepIsCutBackByInterpolationAsScipyDoes) {
  // Steep from 5 in [-10, 10]^5: the first trial (the box's corner, f =
  // 7321105 against 128080) brackets the step; More and Thuente's case of a
  // higher value takes the cubic minimiser or, when the quadratic's is nearer
  // the best step, halfway between the two. scipy's second trial has f =
  // 4.2891567875311809 and is accepted; a bisecting search needs more trials.
  std::vector<double> values;
  const auto steep = [&](const VectorXd& x, double* f, VectorXd* g) {
    Steep(x, f, g);
    values.push_back(*f);
    return true;
  };
  LbfgsbOptions o;
  o.max_iterations = 1;
  const LbfgsbResult r =
      MinimizeLbfgsb(steep, VectorXd::Constant(5, 5), VectorXd::Constant(5, -10), VectorXd::Constant(5, 10), o);
  ASSERT_EQ(values.size(), 3u);
  EXPECT_DOUBLE_EQ(values[0], 128080);
  EXPECT_DOUBLE_EQ(values[1], 7321105);
  EXPECT_NEAR(values[2], 4.2891567875311809, 1e-12 * 4.29);
  EXPECT_EQ(r.f, values[2]);
}

// H g by the two-loop recursion over the pairs (oldest first), H0 = s^T y / y^T y.
VectorXd TwoLoop(const std::deque<VectorXd>& s, const std::deque<VectorXd>& y, const VectorXd& g) {
  const int k = static_cast<int>(s.size());
  std::vector<double> alpha(k);
  VectorXd q = g;
  for (int i = k - 1; i >= 0; --i) {
    alpha[i] = s[i].dot(q) / y[i].dot(s[i]);
    q -= alpha[i] * y[i];
  }
  VectorXd r = (s.back().dot(y.back()) / y.back().squaredNorm()) * q;
  for (int i = 0; i < k; ++i) {
    const double beta = y[i].dot(r) / y[i].dot(s[i]);
    r += s[i] * (alpha[i] - beta);
  }
  return r;
}

TEST(LbfgsbTest, WithoutBoundsEveryStepIsAlongTheTwoLoopRecursionsDirectionAndItConverges) {
  const int n = 12;
  Quadratic q;
  q.a = SpdMatrix(n, 3);
  q.b = VectorXd::LinSpaced(n, -1, 2);
  std::vector<VectorXd> xs, gs;
  LbfgsbOptions o;
  o.memory = 4;
  o.pgtol = 1e-7;
  o.ftol = 0;
  o.on_iteration = [&](const LbfgsbIteration&, const VectorXd& x, const VectorXd& g) {
    xs.push_back(x);
    gs.push_back(g);
    return true;
  };
  const LbfgsbResult r =
      MinimizeLbfgsb(q, VectorXd::Ones(n), VectorXd::Constant(n, -kInf), VectorXd::Constant(n, kInf), o);
  EXPECT_EQ(r.stop, LbfgsbStop::kProjectedGradient) << ToString(r.stop);
  EXPECT_LE((r.x - q.a.ldlt().solve(q.b)).norm(), 1e-6);
  ASSERT_EQ(r.skipped_updates, 0);
  ASSERT_EQ(r.memory_resets, 0);
  ASSERT_GE(xs.size(), 5u);
  std::deque<VectorXd> s, y;
  for (size_t k = 0; k + 1 < xs.size(); ++k) {
    const VectorXd step = xs[k + 1] - xs[k];
    const VectorXd direction = k == 0 ? VectorXd(-gs[0]) : VectorXd(-TwoLoop(s, y, gs[k]));
    const double cosine = step.dot(direction) / (step.norm() * direction.norm());
    EXPECT_GT(cosine, 1 - 1e-9) << "iteration " << k + 1;
    s.push_back(step);
    y.push_back(gs[k + 1] - gs[k]);
    if (static_cast<int>(s.size()) > o.memory) {
      s.pop_front();
      y.pop_front();
    }
  }
}

TEST(LbfgsbTest, EachStoppingTestStopsTheRunWithItsReason) {
  const VectorXd x0 = (VectorXd(4) << -1.2, 1, -1.2, 1).finished();
  const VectorXd lower = VectorXd::Constant(4, -5), upper = VectorXd::Constant(4, 5);
  {
    LbfgsbOptions o;
    o.ftol = 0.05;
    const LbfgsbResult r = MinimizeLbfgsb(Rosenbrock, x0, lower, upper, o);
    ASSERT_EQ(r.stop, LbfgsbStop::kRelativeReduction);
    const auto small = [&](size_t k) {
      const double a = r.history[k - 1].f, b = r.history[k].f;
      return a - b <= o.ftol * std::max({std::abs(a), std::abs(b), 1.0});
    };
    EXPECT_TRUE(small(r.history.size() - 1));
    for (size_t k = 1; k + 1 < r.history.size(); ++k) EXPECT_FALSE(small(k)) << "iteration " << k;
  }
  {
    LbfgsbOptions o;
    o.pgtol = 1e-3;
    o.ftol = 0;
    const LbfgsbResult r = MinimizeLbfgsb(Rosenbrock, x0, lower, upper, o);
    ASSERT_EQ(r.stop, LbfgsbStop::kProjectedGradient);
    EXPECT_LE(r.projected_gradient, 1e-3);
    for (size_t k = 0; k + 1 < r.history.size(); ++k) EXPECT_GT(r.history[k].projected_gradient, 1e-3);
  }
  {
    LbfgsbOptions o;
    o.max_iterations = 3;
    const LbfgsbResult r = MinimizeLbfgsb(Rosenbrock, x0, lower, upper, o);
    EXPECT_EQ(r.stop, LbfgsbStop::kMaxIterations);
    EXPECT_EQ(r.iterations, 3);
    EXPECT_EQ(r.history.size(), 4u);
  }
  {
    LbfgsbOptions o;
    o.max_evaluations = 7;
    const LbfgsbResult r = MinimizeLbfgsb(Rosenbrock, x0, lower, upper, o);
    EXPECT_EQ(r.stop, LbfgsbStop::kMaxEvaluations);
    EXPECT_GT(r.evaluations, 7);
    ASSERT_GE(r.history.size(), 2u);
    EXPECT_LE(r.history[r.history.size() - 2].evaluations, 7);  // the iteration before was within the limit
    EXPECT_EQ(r.history.back().evaluations, r.evaluations);
  }
  {
    LbfgsbOptions o;
    o.on_iteration = [](const LbfgsbIteration& it, const VectorXd&, const VectorXd&) { return it.iteration < 2; };
    const LbfgsbResult r = MinimizeLbfgsb(Rosenbrock, x0, lower, upper, o);
    EXPECT_EQ(r.stop, LbfgsbStop::kCallback);
    EXPECT_EQ(r.iterations, 2);
  }
  {
    // A gradient of the wrong sign: no step along its "descent" direction
    // lowers f, not even from steepest descent.
    const auto wrong = [](const VectorXd& x, double* f, VectorXd* g) {
      *f = x.squaredNorm();
      *g = -2 * x;
      return true;
    };
    const LbfgsbResult r = MinimizeLbfgsb(wrong, x0, lower, upper);
    EXPECT_EQ(r.stop, LbfgsbStop::kLineSearchFailed);
    EXPECT_EQ(r.iterations, 0);
    EXPECT_EQ(r.x, x0);
    EXPECT_EQ(r.evaluations, 1 + LbfgsbOptions().max_line_search_steps);
  }
  EXPECT_STREQ(ToString(LbfgsbStop::kRelativeReduction), "relative reduction <= ftol");
  EXPECT_STREQ(ToString(LbfgsbStop::kProjectedGradient), "projected gradient <= pgtol");
}

TEST(LbfgsbTest, TheStartingPointIsProjectedOntoTheBoxAndAFailureThereStopsTheRun) {
  std::vector<VectorXd> seen;
  const auto failing = [&](const VectorXd& x, double* f, VectorXd* g) {
    seen.push_back(x);
    *f = 0;
    *g = VectorXd::Zero(x.size());
    return false;
  };
  const LbfgsbResult r =
      MinimizeLbfgsb(failing, (VectorXd(2) << 3, -3).finished(), VectorXd::Constant(2, -1), VectorXd::Constant(2, 1));
  EXPECT_EQ(r.stop, LbfgsbStop::kStartFailed);
  EXPECT_STREQ(ToString(r.stop), "start failed");
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], (VectorXd(2) << 1, -1).finished());
  EXPECT_EQ(r.evaluations, 1);
  EXPECT_EQ(r.failed_evaluations, 1);
  EXPECT_TRUE(std::isnan(r.f));
  EXPECT_EQ(r.last_error, "the objective returned false");
  EXPECT_TRUE(r.history.empty());
}

TEST(LbfgsbTest, FailedEvaluationsAreSteppedBackFromAndNeverUsed) {
  // f = |x - 1|^2 on [-10, 10]^2 from (5, 5); every evaluation with a
  // coordinate below -2 fails (the first steepest-descent trial lands on
  // (-3, -3)) in one of three ways.
  for (int way = 0; way < 3; ++way) {
    std::vector<VectorXd> iterates;
    const auto f = [way](const VectorXd& x, double* value, VectorXd* g) -> bool {
      *value = (x.array() - 1).square().sum();
      *g = 2 * (x.array() - 1).matrix();
      if (x.minCoeff() >= -2) return true;
      if (way == 0) return false;
      if (way == 1) {
        *value = std::nan("");
        return true;
      }
      throw std::runtime_error("rollout diverged");
    };
    LbfgsbOptions o;
    o.ftol = 0;
    o.pgtol = 1e-9;
    o.on_iteration = [&](const LbfgsbIteration& it, const VectorXd& x, const VectorXd&) {
      EXPECT_TRUE(std::isfinite(it.f));
      iterates.push_back(x);
      return true;
    };
    const LbfgsbResult r =
        MinimizeLbfgsb(f, VectorXd::Constant(2, 5), VectorXd::Constant(2, -10), VectorXd::Constant(2, 10), o);
    EXPECT_EQ(r.stop, LbfgsbStop::kProjectedGradient) << "way " << way << ": " << ToString(r.stop);
    EXPECT_GE(r.failed_evaluations, 1) << "way " << way;
    EXPECT_LE((r.x - VectorXd::Ones(2)).norm(), 1e-9) << "way " << way;
    for (const VectorXd& x : iterates) EXPECT_GE(x.minCoeff(), -2) << "way " << way;
    const char* expected[3] = {"the objective returned false", "the objective returned a non-finite value",
                               "the objective threw: rollout diverged"};
    EXPECT_EQ(r.last_error, expected[way]);
  }
}

TEST(LbfgsbTest, BadOptionsAndProblemsAreRefusedWithExactMessages) {
  using testing::MessageOf;
  const auto check = [](void (*edit)(LbfgsbOptions*)) {
    LbfgsbOptions o;
    edit(&o);
    return MessageOf<InvalidInputError>([&] { o.Validate(); });
  };
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->memory = 0; }), "L-BFGS-B options: memory = 0 is invalid: must be >= 1");
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->ftol = -1; }),
            "L-BFGS-B options: ftol = -1 is invalid: must be finite and >= 0");
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->pgtol = std::nan(""); }),
            "L-BFGS-B options: pgtol = nan is invalid: must be finite and >= 0");
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->max_iterations = 0; }),
            "L-BFGS-B options: max_iterations = 0 is invalid: must be >= 1");
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->max_evaluations = -3; }),
            "L-BFGS-B options: max_evaluations = -3 is invalid: must be >= 1");
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->max_line_search_steps = 0; }),
            "L-BFGS-B options: max_line_search_steps = 0 is invalid: must be >= 1");
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->sufficient_decrease = 1; }),
            "L-BFGS-B options: sufficient_decrease = 1 is invalid: must be in (0, 1)");
  EXPECT_EQ(check([](LbfgsbOptions* o) { o->curvature = 1e-4; }),
            "L-BFGS-B options: curvature = 0.0001 is invalid: must be in (sufficient_decrease, 1)");
  const VectorXd one = VectorXd::Zero(1), two = VectorXd::Zero(2);
  const auto minimise = [](const VectorXd& x0, const VectorXd& lower, const VectorXd& upper) {
    return MessageOf<InvalidInputError>([&] { MinimizeLbfgsb(Rosenbrock, x0, lower, upper); });
  };
  EXPECT_EQ(minimise(VectorXd(), VectorXd(), VectorXd()),
            "L-BFGS-B: x0 is empty: the problem needs at least one variable");
  EXPECT_EQ(minimise(two, one, two), "L-BFGS-B: lower has 1 entries and upper 2, expected 2 each (the size of x0)");
  EXPECT_EQ(minimise((VectorXd(2) << 0, kInf).finished(), two, two),
            "L-BFGS-B: x0(1) = inf is invalid: must be finite");
  EXPECT_EQ(minimise(two, (VectorXd(2) << 0, std::nan("")).finished(), two),
            "L-BFGS-B: bound 1 is NaN: use -inf or +inf for a missing bound");
  EXPECT_EQ(minimise(two, (VectorXd(2) << 0, 1).finished(), two),
            "L-BFGS-B: lower(1) = 1 > upper(1) = 0: every lower bound must be <= its upper bound");
}

}  // namespace
}  // namespace diffpd::solvers
