#include "diffpd/solvers/ceres/coordinate_manifold.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

// x moved into the open interval of `m` (the logistic rounds to 0 or 1 for
// large |u|): the nearest double inside.
double Inside(const CoordinateMap& m, double x) {
  return std::clamp(x, std::nextafter(m.lower, m.upper), std::nextafter(m.upper, m.lower));
}

}  // namespace

CoordinateManifold::CoordinateManifold(std::vector<CoordinateMap> coordinates) : maps_(std::move(coordinates)) {
  if (maps_.empty()) throw InvalidInputError("CoordinateManifold: needs at least one coordinate");
  for (size_t i = 0; i < maps_.size(); ++i) {
    const CoordinateMap& m = maps_[i];
    const bool interval = m.kind == CoordinateMap::Kind::kLogit || m.kind == CoordinateMap::Kind::kLogLogit;
    if (interval && !(std::isfinite(m.lower) && std::isfinite(m.upper) && m.lower < m.upper)) {
      std::ostringstream msg;
      msg << "CoordinateManifold: coordinate " << i << " has the empty interval (" << m.lower << ", " << m.upper << ")";
      throw InvalidInputError(msg.str());
    }
    if (m.kind == CoordinateMap::Kind::kLogLogit && !(m.lower > 0)) {
      std::ostringstream msg;
      msg << "CoordinateManifold: coordinate " << i << " has the log-logit interval (" << m.lower << ", " << m.upper
          << "): needs 0 < lower";
      throw InvalidInputError(msg.str());
    }
  }
}

bool CoordinateManifold::InDomain(int i, double x) const {
  switch (maps_[i].kind) {
    case CoordinateMap::Kind::kLinear:
      return std::isfinite(x);
    case CoordinateMap::Kind::kLog:
      return x > 0 && std::isfinite(x);
    case CoordinateMap::Kind::kLogit:
    case CoordinateMap::Kind::kLogLogit:
      return x > maps_[i].lower && x < maps_[i].upper;
  }
  return false;
}

double CoordinateManifold::ToTangent(int i, double x) const {
  const CoordinateMap& m = maps_[i];
  switch (m.kind) {
    case CoordinateMap::Kind::kLinear:
      return x;
    case CoordinateMap::Kind::kLog:
      return std::log(x);
    case CoordinateMap::Kind::kLogit:
      return std::log((x - m.lower) / (m.upper - x));
    case CoordinateMap::Kind::kLogLogit: {
      const double s = std::log(x / m.lower) / std::log(m.upper / m.lower);
      return std::log(s / (1 - s));
    }
  }
  return x;
}

double CoordinateManifold::FromTangent(int i, double u) const {
  const CoordinateMap& m = maps_[i];
  switch (m.kind) {
    case CoordinateMap::Kind::kLinear:
      return u;
    case CoordinateMap::Kind::kLog:
      return std::exp(u);
    case CoordinateMap::Kind::kLogit: {
      // Stable logistic: never exp of a large positive number.
      const double s = u >= 0 ? 1 / (1 + std::exp(-u)) : std::exp(u) / (1 + std::exp(u));
      return Inside(m, m.lower + (m.upper - m.lower) * s);
    }
    case CoordinateMap::Kind::kLogLogit: {
      const double s = u >= 0 ? 1 / (1 + std::exp(-u)) : std::exp(u) / (1 + std::exp(u));
      return Inside(m, m.lower * std::exp(std::log(m.upper / m.lower) * s));
    }
  }
  return u;
}

double CoordinateManifold::Derivative(int i, double x) const {
  const CoordinateMap& m = maps_[i];
  switch (m.kind) {
    case CoordinateMap::Kind::kLinear:
      return 1;
    case CoordinateMap::Kind::kLog:
      return x;
    case CoordinateMap::Kind::kLogit:
      return (x - m.lower) * (m.upper - x) / (m.upper - m.lower);
    case CoordinateMap::Kind::kLogLogit: {
      const double span = std::log(m.upper / m.lower), s = std::log(x / m.lower) / span;
      return x * span * s * (1 - s);
    }
  }
  return 1;
}

bool CoordinateManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  for (int i = 0; i < AmbientSize(); ++i) {
    if (!InDomain(i, x[i])) return false;
    x_plus_delta[i] =
        maps_[i].kind == CoordinateMap::Kind::kLinear ? x[i] + delta[i] : FromTangent(i, ToTangent(i, x[i]) + delta[i]);
  }
  return true;
}

bool CoordinateManifold::PlusJacobian(const double* x, double* jacobian) const {
  const int n = AmbientSize();
  for (int k = 0; k < n * n; ++k) jacobian[k] = 0;
  for (int i = 0; i < n; ++i) {
    if (!InDomain(i, x[i])) return false;
    jacobian[i * n + i] = Derivative(i, x[i]);
  }
  return true;
}

bool CoordinateManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  for (int i = 0; i < AmbientSize(); ++i) {
    if (!InDomain(i, x[i]) || !InDomain(i, y[i])) return false;
    y_minus_x[i] =
        maps_[i].kind == CoordinateMap::Kind::kLinear ? y[i] - x[i] : ToTangent(i, y[i]) - ToTangent(i, x[i]);
  }
  return true;
}

bool CoordinateManifold::MinusJacobian(const double* x, double* jacobian) const {
  const int n = AmbientSize();
  for (int k = 0; k < n * n; ++k) jacobian[k] = 0;
  for (int i = 0; i < n; ++i) {
    if (!InDomain(i, x[i])) return false;
    jacobian[i * n + i] = 1 / Derivative(i, x[i]);
  }
  return true;
}

}  // namespace diffpd::solvers
