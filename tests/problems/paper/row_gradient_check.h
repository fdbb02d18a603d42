// The shared central-difference check of a paper row's gradient dL/dx.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "diffpd/simulator.h"
#include "paper/paper_row.h"
#include "paper/row_evaluation.h"

namespace diffpd::problems::testing {

// Compares dL/dx . d with (L(x + eps d) - L(x - eps d)) / (2 eps) at x_init
// along `directions` random directions d (entries N(0, 1) times the
// variable's range: its bounds' width, or max(|x_j|, 1e-3) where unbounded),
// eps = 1e-4, with every solve converged tightly (`method`, relative
// tolerance 1e-10 of the start residual, adjoint 1e-12, one thread). Expects the relative error
// |fd - adjoint| / max(|fd|, |adjoint|) <= tolerance for each direction.
inline void ExpectRowGradientMatchesCentralDifferences(PaperRow row, int directions = 2, double tolerance = 1e-4,
                                                       Method method = Method::kPdLbfgs) {
  SolverOptions options = row.Options(method, 1);
  options.rel_tolerance = 1e-10;
  options.tolerance_reference = ToleranceReference::kStartResidual;
  options.abs_tolerance = 1e-13;
  options.backward_rel_tolerance = 1e-12;
  row.Prepare(options);
  Simulator sim(row.scene, options);
  const VectorXd x = row.initial();
  const RowEvaluation at_x = EvaluateRow(row, &sim, x, true);
  ASSERT_EQ(at_x.gradient.size(), x.size());
  const VectorXd lower = row.lower(), upper = row.upper();
  std::mt19937 rng(20211);
  std::normal_distribution<double> normal;
  const double eps = 1e-4;
  for (int k = 0; k < directions; ++k) {
    VectorXd d(x.size());
    for (Eigen::Index j = 0; j < x.size(); ++j) {
      const double range = std::isfinite(upper(j) - lower(j)) ? upper(j) - lower(j) : std::max(std::abs(x(j)), 1e-3);
      d(j) = normal(rng) * range;
    }
    const double plus = EvaluateRow(row, &sim, x + eps * d, false).loss;
    const double minus = EvaluateRow(row, &sim, x - eps * d, false).loss;
    const double fd = (plus - minus) / (2 * eps), adjoint = at_x.gradient.dot(d);
    const double error = std::abs(fd - adjoint) / std::max({std::abs(fd), std::abs(adjoint), 1e-300});
    EXPECT_LE(error, tolerance) << row.name << " direction " << k << ": adjoint " << adjoint << ", central difference "
                                << fd;
  }
}

}  // namespace diffpd::problems::testing
