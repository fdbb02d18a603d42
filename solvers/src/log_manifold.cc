#include "diffpd/solvers/log_manifold.h"

#include <cmath>

#include "diffpd/error.h"

namespace diffpd::solvers {

LogManifold::LogManifold(std::vector<bool> log_coordinates) : log_(std::move(log_coordinates)) {
  if (log_.empty()) throw InvalidInputError("LogManifold: needs at least one coordinate");
}

bool LogManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  for (size_t i = 0; i < log_.size(); ++i) {
    if (log_[i]) {
      if (!(x[i] > 0)) return false;
      x_plus_delta[i] = x[i] * std::exp(delta[i]);
    } else {
      x_plus_delta[i] = x[i] + delta[i];
    }
    if (!std::isfinite(x_plus_delta[i])) return false;
  }
  return true;
}

bool LogManifold::PlusJacobian(const double* x, double* jacobian) const {
  const size_t n = log_.size();
  for (size_t i = 0; i < n * n; ++i) jacobian[i] = 0;
  for (size_t i = 0; i < n; ++i) {
    if (log_[i] && !(x[i] > 0)) return false;
    jacobian[i * n + i] = log_[i] ? x[i] : 1.0;
  }
  return true;
}

bool LogManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  for (size_t i = 0; i < log_.size(); ++i) {
    if (log_[i]) {
      if (!(x[i] > 0) || !(y[i] > 0)) return false;
      y_minus_x[i] = std::log(y[i] / x[i]);
    } else {
      y_minus_x[i] = y[i] - x[i];
    }
  }
  return true;
}

bool LogManifold::MinusJacobian(const double* x, double* jacobian) const {
  const size_t n = log_.size();
  for (size_t i = 0; i < n * n; ++i) jacobian[i] = 0;
  for (size_t i = 0; i < n; ++i) {
    if (log_[i] && !(x[i] > 0)) return false;
    jacobian[i * n + i] = log_[i] ? 1.0 / x[i] : 1.0;
  }
  return true;
}

}  // namespace diffpd::solvers
