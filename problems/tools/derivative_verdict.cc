#include "tools/derivative_verdict.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace diffpd::problems {
namespace {

int Rank(CheckVerdict v) { return v == CheckVerdict::kPass ? 0 : v == CheckVerdict::kUnresolved ? 1 : 2; }

}  // namespace

const char* ToString(CheckVerdict verdict) {
  switch (verdict) {
    case CheckVerdict::kPass:
      return "pass";
    case CheckVerdict::kFail:
      return "fail";
    case CheckVerdict::kUnresolved:
      return "unresolved";
  }
  return "unknown";
}

CheckVerdict Worse(CheckVerdict a, CheckVerdict b) { return Rank(a) >= Rank(b) ? a : b; }

std::string FormatTwoDigits(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2g", v);
  return buffer;
}

DerivativeJudgement JudgeDerivative(double analytic, const std::vector<FiniteDifference>& differences, double tolerance,
                                    bool extrapolate) {
  std::vector<FiniteDifferenceVector> vectors;
  vectors.reserve(differences.size());
  for (const FiniteDifference& d : differences) vectors.push_back({d.step, {d.value}, d.noise, d.bound});
  return JudgeDerivative(std::vector<double>{analytic}, vectors, tolerance, extrapolate);
}

namespace {

using Vector = std::vector<double>;

double Distance(const Vector& a, const Vector& b) {
  double sum = 0;
  for (size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
  return std::sqrt(sum);
}

double Norm(const Vector& a) {
  double sum = 0;
  for (double v : a) sum += v * v;
  return std::sqrt(sum);
}

// A sequence of estimates of the derivative at decreasing steps, with the
// divisor that turns the distance to the previous (larger-step) estimate into
// this one's truncation (index 0 has none).
struct Estimates {
  std::vector<FiniteDifferenceVector> at;
  std::vector<double> divisor;
};

// The uncertainty of at[k] (see the header); the last estimate only probes
// its neighbour's noise unless it is the only one.
double Uncertainty(const Estimates& s, size_t k) {
  const size_t n = s.at.size();
  const FiniteDifferenceVector& d = s.at[k];
  double u = d.noise;
  if (k > 0) {
    u = std::max(u, Distance(s.at[k - 1].value, d.value) / s.divisor[k]);
  } else if (n > 1) {
    // No larger step: the truncation is at most the distance to the next
    // estimate plus that one's own noise (measured from the one after it),
    // which can hide the truncation by cancelling it.
    double next_noise = s.at[1].noise;
    if (n > 2) next_noise = std::max(next_noise, Distance(s.at[2].value, s.at[1].value) * s.at[2].step / s.at[1].step);
    u = std::max(u, Distance(s.at[1].value, d.value) + next_noise);
  }
  if (k + 1 < n) u = std::max(u, Distance(s.at[k + 1].value, d.value) * s.at[k + 1].step / d.step);
  return std::isfinite(u) ? u : std::numeric_limits<double>::infinity();
}

DerivativeJudgement Judge(const Vector& analytic, const Estimates& s, double tolerance) {
  const size_t n = s.at.size();
  const size_t candidates = n > 1 ? n - 1 : 1;
  size_t best = 0;
  double best_uncertainty = Uncertainty(s, 0);
  for (size_t k = 1; k < candidates; ++k) {
    const double u = Uncertainty(s, k);
    if (u < best_uncertainty) {
      best_uncertainty = u;
      best = k;
    }
  }
  const FiniteDifferenceVector& d = s.at[best];
  DerivativeJudgement j;
  j.step = d.step;
  j.tolerance = tolerance;
  const double scale = std::max(Norm(d.value), Norm(analytic));
  const double difference = Distance(d.value, analytic);
  if (!std::isfinite(Norm(d.value))) {
    j.error = j.floor = j.bound = std::numeric_limits<double>::infinity();
  } else if (scale > 0) {
    j.error = difference / scale;
    j.floor = best_uncertainty / scale;
    j.bound = d.bound / scale;
  } else {  // both exactly zero
    j.error = 0;
    j.floor = best_uncertainty > 0 ? std::numeric_limits<double>::infinity() : 0;
    j.bound = d.bound > 0 ? std::numeric_limits<double>::infinity() : 0;
  }
  const double worst = std::max(j.error, j.floor);
  j.margin = worst > 0 ? tolerance / worst : std::numeric_limits<double>::infinity();
  if (j.error <= tolerance && j.floor <= tolerance) {
    j.verdict = CheckVerdict::kPass;
  } else if (j.error > tolerance && j.error > 3 * j.floor && j.error > j.bound) {
    j.verdict = CheckVerdict::kFail;
    j.reason = "differs by " + FormatTwoDigits(j.error) + " relative, above the tolerance " +
               FormatTwoDigits(tolerance) + ", 3x the noise floor " + FormatTwoDigits(j.floor) +
               " and the solves' worst case " + FormatTwoDigits(j.bound);
  } else if (j.floor <= tolerance) {
    j.verdict = CheckVerdict::kUnresolved;
    j.reason = "differs by " + FormatTwoDigits(j.error) + " relative, within the worst case " +
               FormatTwoDigits(j.bound) + " the solves' residuals allow (tolerance " + FormatTwoDigits(tolerance) + ")";
  } else {
    j.verdict = CheckVerdict::kUnresolved;
    j.reason = "the differences resolve the derivative only to " + FormatTwoDigits(j.floor) + " relative (tolerance " +
               FormatTwoDigits(tolerance) + "; error " + FormatTwoDigits(j.error) + ")";
  }
  return j;
}

}  // namespace

DerivativeJudgement JudgeDerivative(const Vector& analytic, const std::vector<FiniteDifferenceVector>& differences,
                                    double tolerance, bool extrapolate) {
  if (differences.empty()) throw std::invalid_argument("JudgeDerivative: no differences");
  if (!(tolerance > 0))
    throw std::invalid_argument("JudgeDerivative: tolerance = " + FormatTwoDigits(tolerance) + " must be > 0");
  for (const FiniteDifferenceVector& d : differences)
    if (d.value.size() != analytic.size())
      throw std::invalid_argument("JudgeDerivative: a difference has " + std::to_string(d.value.size()) +
                                  " entries, the derivative " + std::to_string(analytic.size()));
  const size_t n = differences.size();
  Estimates plain{differences, std::vector<double>(n, 0.0)};
  for (size_t k = 1; k < n; ++k) {
    const double r = differences[k - 1].step / differences[k].step;
    double divisor = r * r - 1;
    if (k > 1) {
      // First-order truncation: a loss that is C1 but not C2 in the input
      // (|u| u drag on a body starting at rest, whose velocities the
      // perturbation sets) makes fd(e) - fd(0) ~ e, not e^2. Where the
      // differences shrink towards e_k as e but not as e^2 (by less than
      // r^1.5 a step while still shrinking, so not noise, which grows as e
      // falls), the truncation at e_k is their distance / (r - 1).
      const double inner = Distance(differences[k - 1].value, differences[k].value);
      const double outer = Distance(differences[k - 2].value, differences[k - 1].value);
      const double r_outer = differences[k - 2].step / differences[k - 1].step;
      if (outer > inner && outer < std::pow(r_outer, 1.5) * inner) divisor = r - 1;
    }
    plain.divisor[k] = divisor;
  }
  DerivativeJudgement j = Judge(analytic, plain, tolerance);
  if (!extrapolate || n < 3) return j;
  // Richardson extrapolation: x_k = fd(e_k) + (fd(e_k) - fd(e_k-1)) / divisor_k
  // removes the leading truncation term; its own truncation is measured
  // from x_k-1 with the same divisor, which over-estimates it wherever x
  // converges faster than fd (by r^2 for a smooth loss).
  Estimates extrapolated;
  for (size_t k = 1; k < n; ++k) {
    const FiniteDifferenceVector& d = differences[k];
    const FiniteDifferenceVector& larger = differences[k - 1];
    const double p = plain.divisor[k];
    FiniteDifferenceVector x{d.step, d.value, d.noise * (1 + 1 / p) + larger.noise / p,
                             d.bound * (1 + 1 / p) + larger.bound / p};
    for (size_t i = 0; i < x.value.size(); ++i) x.value[i] += (d.value[i] - larger.value[i]) / p;
    extrapolated.at.push_back(std::move(x));
    extrapolated.divisor.push_back(extrapolated.at.size() > 1 ? p : 0.0);
  }
  DerivativeJudgement x = Judge(analytic, extrapolated, tolerance);
  // Extrapolation may confirm a derivative with a larger margin, where the
  // derivative lies within 3x the extrapolation's own measured uncertainty
  // (beyond that the uncertainty is not trusted: the loss is not smooth over
  // the steps, e.g. a kink inside them); it never fails one or leaves one
  // unresolved that the differences themselves judge.
  if (x.verdict == CheckVerdict::kPass && x.error <= 3 * x.floor &&
      (j.verdict != CheckVerdict::kPass || x.margin > j.margin)) {
    x.extrapolated = true;
    return x;
  }
  return j;
}

}  // namespace diffpd::problems
