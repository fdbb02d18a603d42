// The derivative check of a RolloutFunction against central differences of
// its own values, used on every parameter block's case
// (parameter_block_cases.h).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "diffpd/solvers/core/rollout_function.h"

namespace diffpd::testing {

// At `point`, with central differences D (the five-point stencil, step
// steps_j for parameter j: truncation O(h^4), so steps can be large enough
// that the rollouts' solver noise divided by the step stays below 1e-9 of a
// row; with the three-point stencil at 1e-4 of a typical value, Poisson's
// ratio's column was within 1.5x of the tolerance):
//  - the reverse-mode Jacobian J of every row: |J_rj - D_rj| <= tolerance *
//    max(|D_rj|, 1e-2 max_j |D_rj|);
//  - the forward-mode Jacobian (when forward mode is available) equals J
//    within 1e-8 of each row's largest entry;
//  - Gradient(w) = J^T w for fixed weights w (within 1e-10 relative);
//  - declared zeros are zeros: |D_rj| <= 1e-8 max_j |D_rj| wherever
//    FirstAffectedState(j) > LastState(r).
inline void ExpectDerivativesMatchCentralDifferences(solvers::RolloutFunction* f, const VectorXd& point,
                                                     const VectorXd& steps, double tolerance) {
  const int n = f->num_parameters(), m = f->num_rows();
  ASSERT_EQ(point.size(), n);
  ASSERT_EQ(steps.size(), n);
  const std::vector<int> rows = f->AllRows();
  MatrixXd differences(m, n);
  for (int j = 0; j < n; ++j) {
    VectorXd values_at[4];
    const double offsets[4] = {-2, -1, 1, 2};
    for (int k = 0; k < 4; ++k) {
      VectorXd shifted = point;
      shifted(j) += offsets[k] * steps(j);
      ASSERT_TRUE(f->Evaluate(shifted, rows, &values_at[k], nullptr)) << f->statistics().last_error;
    }
    differences.col(j) = (8 * (values_at[2] - values_at[1]) - (values_at[3] - values_at[0])) / (12 * steps(j));
  }
  f->SetDerivativeMode(solvers::DerivativeMode::kReverse);
  MatrixXd reverse;
  VectorXd values;
  ASSERT_TRUE(f->Evaluate(point, rows, &values, &reverse)) << f->statistics().last_error;
  for (int r = 0; r < m; ++r) {
    const double scale = differences.row(r).cwiseAbs().maxCoeff();
    EXPECT_GT(scale, 0) << "row " << r << " depends on no parameter";
    for (int j = 0; j < n; ++j) {
      const double d = differences(r, j);
      EXPECT_NEAR(reverse(r, j), d, tolerance * std::max(std::abs(d), 1e-2 * scale))
          << "row " << r << " parameter " << j;
      if (f->FirstAffectedState(j) > f->LastState(r)) {
        EXPECT_LE(std::abs(d), 1e-8 * scale) << "row " << r << " parameter " << j << " is declared zero";
      }
    }
  }
  if (f->ForwardModeAvailable()) {
    f->SetDerivativeMode(solvers::DerivativeMode::kForward);
    MatrixXd forward;
    ASSERT_TRUE(f->Evaluate(point, rows, nullptr, &forward)) << f->statistics().last_error;
    for (int r = 0; r < m; ++r)
      EXPECT_LE((forward.row(r) - reverse.row(r)).cwiseAbs().maxCoeff(), 1e-8 * reverse.row(r).cwiseAbs().maxCoeff())
          << "row " << r;
  }
  f->SetDerivativeMode(solvers::DerivativeMode::kAuto);
  VectorXd weights(m), gradient;
  for (int r = 0; r < m; ++r) weights(r) = 1.0 / (1.0 + r) / std::max(reverse.row(r).cwiseAbs().maxCoeff(), 1e-300);
  double value = 0;
  ASSERT_TRUE(f->Gradient(point, weights, &gradient, &value)) << f->statistics().last_error;
  EXPECT_NEAR(value, weights.dot(values), 1e-14 * weights.cwiseAbs().dot(values.cwiseAbs()));
  const VectorXd expected = reverse.transpose() * weights;
  EXPECT_LE((gradient - expected).cwiseAbs().maxCoeff(), 1e-10 * expected.cwiseAbs().maxCoeff());
}

}  // namespace diffpd::testing
