#include "tools/derivative_verdict.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace diffpd::problems {
namespace {

std::string Format(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2g", v);
  return buffer;
}

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

DerivativeJudgement JudgeDerivative(double analytic, const std::vector<FiniteDifference>& differences,
                                    double tolerance) {
  std::vector<FiniteDifferenceVector> vectors;
  vectors.reserve(differences.size());
  for (const FiniteDifference& d : differences) vectors.push_back({d.step, {d.value}, d.noise, d.bound});
  return JudgeDerivative(std::vector<double>{analytic}, vectors, tolerance);
}

DerivativeJudgement JudgeDerivative(const std::vector<double>& analytic,
                                    const std::vector<FiniteDifferenceVector>& differences, double tolerance) {
  if (differences.empty()) throw std::invalid_argument("JudgeDerivative: no differences");
  if (!(tolerance > 0))
    throw std::invalid_argument("JudgeDerivative: tolerance = " + Format(tolerance) + " must be > 0");
  for (const FiniteDifferenceVector& d : differences)
    if (d.value.size() != analytic.size())
      throw std::invalid_argument("JudgeDerivative: a difference has " + std::to_string(d.value.size()) +
                                  " entries, the derivative " + std::to_string(analytic.size()));
  auto distance = [](const std::vector<double>& a, const std::vector<double>& b) {
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(sum);
  };
  auto norm = [](const std::vector<double>& a) {
    double sum = 0;
    for (double v : a) sum += v * v;
    return std::sqrt(sum);
  };
  const size_t n = differences.size();
  // The uncertainty of fd(e_k) (see the header); the smallest step only
  // probes its neighbour's noise unless it is the only one.
  auto uncertainty = [&](size_t k) {
    const FiniteDifferenceVector& d = differences[k];
    double u = d.noise;
    if (k > 0) {
      const double r = differences[k - 1].step / d.step;
      const double inner = distance(differences[k - 1].value, d.value);
      double divisor = r * r - 1;
      if (k > 1) {
        // First-order truncation: a loss that is C1 but not C2 in the input
        // (|u| u drag on a body starting at rest, whose velocities the
        // perturbation sets) makes fd(e) - fd(0) ~ e, not e^2. Where the
        // differences shrink towards e_k as e but not as e^2 (by less than
        // r^1.5 a step while still shrinking, so not noise, which grows as e
        // falls), the truncation at e_k is their distance / (r - 1).
        const double outer = distance(differences[k - 2].value, differences[k - 1].value);
        const double r_outer = differences[k - 2].step / differences[k - 1].step;
        if (outer > inner && outer < std::pow(r_outer, 1.5) * inner) divisor = r - 1;
      }
      u = std::max(u, inner / divisor);
    } else if (n > 1) {
      // No larger step: the truncation is at most the distance to the next
      // difference plus that difference's own noise (measured from the one
      // after it), which can hide the truncation by cancelling it.
      double next_noise = differences[1].noise;
      if (n > 2)
        next_noise = std::max(next_noise, distance(differences[2].value, differences[1].value) * differences[2].step /
                                              differences[1].step);
      u = std::max(u, distance(differences[1].value, d.value) + next_noise);
    }
    if (k + 1 < n) u = std::max(u, distance(differences[k + 1].value, d.value) * differences[k + 1].step / d.step);
    return std::isfinite(u) ? u : std::numeric_limits<double>::infinity();
  };
  const size_t candidates = n > 1 ? n - 1 : 1;
  size_t best = 0;
  double best_uncertainty = uncertainty(0);
  for (size_t k = 1; k < candidates; ++k) {
    const double u = uncertainty(k);
    if (u < best_uncertainty) {
      best_uncertainty = u;
      best = k;
    }
  }
  const FiniteDifferenceVector& d = differences[best];
  DerivativeJudgement j;
  j.step = d.step;
  j.tolerance = tolerance;
  const double scale = std::max(norm(d.value), norm(analytic));
  const double difference = distance(d.value, analytic);
  if (!std::isfinite(norm(d.value))) {
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
    j.reason = "differs by " + Format(j.error) + " relative, above the tolerance " + Format(tolerance) +
               ", 3x the noise floor " + Format(j.floor) + " and the solves' worst case " + Format(j.bound);
  } else if (j.floor <= tolerance) {
    j.verdict = CheckVerdict::kUnresolved;
    j.reason = "differs by " + Format(j.error) + " relative, within the worst case " + Format(j.bound) +
               " the solves' residuals allow (tolerance " + Format(tolerance) + ")";
  } else {
    j.verdict = CheckVerdict::kUnresolved;
    j.reason = "the differences resolve the derivative only to " + Format(j.floor) + " relative (tolerance " +
               Format(tolerance) + "; error " + Format(j.error) + ")";
  }
  return j;
}

}  // namespace diffpd::problems
