// Linear constraints on the decision variables of a trajectory optimisation:
//   lower <= sum_j coefficients[j] * x[columns[j]] <= upper.
// Their Jacobian is constant and exactly as sparse as `columns`.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "diffpd/solvers/core/control_signal.h"

namespace diffpd::solvers {

struct LinearConstraint {
  std::vector<int> columns;          // distinct variable indices
  std::vector<double> coefficients;  // same length as columns
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  std::string name = "linear";

  // Throws InvalidInputError naming the constraint: sizes differ, a column
  // is < 0 or >= num_variables or repeats, a coefficient is not finite,
  // a bound is NaN, or lower > upper.
  void Validate(int num_variables) const;
};

// lower <= s_k <= upper for every step k of a linear signal (is_linear())
// whose coefficients are the variables offset .. offset + p - 1: one row per
// distinct row of the signal's basis (rows repeated by a periodic signal
// are listed once). Throws InvalidInputError for a nonlinear signal.
std::vector<LinearConstraint> SignalRangeConstraints(const ControlSignal& signal, int offset, double lower,
                                                     double upper, const std::string& name = "signal_range");

}  // namespace diffpd::solvers
