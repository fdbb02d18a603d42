// Log-space steps for positive parameters, as a ceres::Manifold.
//
// The parameter block keeps its physical values (e.g. E in Pa), but the
// optimiser steps coordinate i multiplicatively when log_coordinates[i]:
//   Plus(x, delta)_i  = x_i exp(delta_i)      (log coordinates, x_i > 0)
//                     = x_i + delta_i          (the others)
//   Minus(y, x)_i     = log(y_i / x_i)  or  y_i - x_i,
// so x_i stays positive, a step of delta = 0.1 changes E by about 10% at any
// scale, and bounds (ceres::Problem::SetParameterLower/UpperBound, applied to
// the physical values) still work. PlusJacobian = diag(x_i or 1) at delta = 0.
#pragma once

#include <vector>

#include <ceres/manifold.h>

namespace diffpd::solvers {

class LogManifold : public ceres::Manifold {
 public:
  // One flag per coordinate of the block (true: log space). Throws
  // InvalidInputError if the list is empty.
  explicit LogManifold(std::vector<bool> log_coordinates);

  int AmbientSize() const override { return static_cast<int>(log_.size()); }
  int TangentSize() const override { return static_cast<int>(log_.size()); }
  // False if a log coordinate of x (or y) is not > 0 or a result is not finite.
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  std::vector<bool> log_;
};

}  // namespace diffpd::solvers
