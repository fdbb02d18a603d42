// Per-coordinate reparameterisations of a parameter block as a
// ceres::Manifold: positivity (log space) and open intervals (logit, on the
// value or on its logarithm).
//
// The block keeps its physical values (E in Pa, nu dimensionless), and each
// coordinate is x = phi(u) for an unconstrained u in which the optimiser
// steps:
//   linear:  phi(u) = u                                (any x)
//   log:     phi(u) = exp(u)                           (x > 0)
//   logit:   phi(u) = lo + (hi - lo) / (1 + exp(-u))   (lo < x < hi)
//   log-logit: phi(u) = lo (hi / lo)^s(u), s(u) = 1 / (1 + exp(-u))
//                                                      (0 < lo < x < hi)
// so Plus(x, delta) = phi(phi^-1(x) + delta), Minus(y, x) = phi^-1(y) -
// phi^-1(x), PlusJacobian = diag(phi'(phi^-1(x))) = diag(1, x,
// (x - lo)(hi - x) / (hi - lo), x log(hi / lo) s (1 - s)). A log step of 0.1
// changes E by about 10% at any scale; a logit coordinate never leaves its
// interval (Poisson's ratio in (0, 0.5)); a log-logit coordinate does both
// (E in (1e4, 5e6) Pa, steps relative inside the interval). Ceres' parameter bounds (SetParameterLower/UpperBound)
// apply to the physical values and may be combined with any map.
#pragma once

#include <vector>

#include <ceres/manifold.h>

namespace diffpd::solvers {

struct CoordinateMap {
  enum class Kind { kLinear, kLog, kLogit, kLogLogit };
  Kind kind = Kind::kLinear;
  double lower = 0;  // kLogit, kLogLogit: the open interval (lower, upper)
  double upper = 1;

  static CoordinateMap Linear() { return {Kind::kLinear, 0, 1}; }
  static CoordinateMap Log() { return {Kind::kLog, 0, 1}; }
  static CoordinateMap Logit(double lower, double upper) { return {Kind::kLogit, lower, upper}; }
  static CoordinateMap LogLogit(double lower, double upper) { return {Kind::kLogLogit, lower, upper}; }
};

class CoordinateManifold : public ceres::Manifold {
 public:
  // One map per coordinate of the block. Throws InvalidInputError if the
  // list is empty, a logit interval is not finite with lower < upper, or a
  // log-logit interval's lower end is not > 0:
  //   "CoordinateManifold: coordinate 1 has the empty interval (0.5, 0.5)",
  //   "CoordinateManifold: coordinate 0 has the log-logit interval (0, 1): needs 0 < lower".
  explicit CoordinateManifold(std::vector<CoordinateMap> coordinates);

  int AmbientSize() const override { return static_cast<int>(maps_.size()); }
  int TangentSize() const override { return static_cast<int>(maps_.size()); }
  // All return false if a coordinate of x (or y) lies outside its map's
  // domain. For huge steps (Ceres probes Plus(x, -gradient) with raw
  // gradients) Plus returns +inf for log, and for logit and log-logit the
  // nearest double inside the interval (where PlusJacobian is about 0: the
  // coordinate is stuck at its bound, and Ceres may go on).
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  bool InDomain(int i, double x) const;
  double ToTangent(int i, double x) const;    // phi^-1
  double FromTangent(int i, double u) const;  // phi
  double Derivative(int i, double x) const;   // phi'(phi^-1(x))
  std::vector<CoordinateMap> maps_;
};

}  // namespace diffpd::solvers
