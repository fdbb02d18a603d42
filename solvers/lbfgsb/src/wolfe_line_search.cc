#include "wolfe_line_search.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace diffpd::solvers::lbfgsb_internal {
namespace {

struct Trial {
  double step = 0, f = 0, slope = 0;
  bool failed = false;  // the evaluation failed: no value, only an upper end
  VectorXd x, gradient;
};

// The minimiser of the cubic through (a, fa, da) and (b, fb, db); the
// quadratic's through (a, fa, da) and (a, fb) when the cubic has none; NaN
// when neither has.
double Interpolate(const Trial& a, const Trial& b) {
  const double h = b.step - a.step;
  if (!b.failed) {
    const double d1 = a.slope + b.slope - 3 * (a.f - b.f) / (a.step - b.step);
    const double disc = d1 * d1 - a.slope * b.slope;
    if (disc >= 0) {
      const double d2 = std::copysign(std::sqrt(disc), h);
      const double denom = b.slope - a.slope + 2 * d2;
      if (denom != 0) {
        const double t = b.step - h * (b.slope + d2 - d1) / denom;
        if (std::isfinite(t)) return t;
      }
    }
    const double curvature = b.f - a.f - a.slope * h;
    if (curvature > 0) return a.step - a.slope * h * h / (2 * curvature);
  }
  return std::nan("");
}

}  // namespace

LineSearchResult StrongWolfeLineSearch(const Evaluator& evaluate, const VectorXd& x, double f0, const VectorXd& g0,
                                       const VectorXd& xbar, double step0, double step_max, const VectorXd& lower,
                                       const VectorXd& upper, const LineSearchSettings& settings) {
  LineSearchResult out;
  const VectorXd d = xbar - x;
  const double slope0 = g0.dot(d);
  if (!(slope0 < 0) || !(step_max > 0)) return out;
  Trial lo;  // the best point with sufficient decrease so far (the start at first)
  lo.step = 0;
  lo.f = f0;
  lo.slope = slope0;
  Trial hi;  // the other end once bracketed
  bool bracketed = false;
  double step = std::min(step0, step_max);
  const auto accept = [&](const Trial& t, bool wolfe) {
    out.accepted = true;
    out.strong_wolfe = wolfe;
    out.step = t.step;
    out.x = t.x;
    out.gradient = t.gradient;
    out.f = t.f;
  };
  for (int k = 0; k < settings.max_steps; ++k) {
    Trial t;
    t.step = step;
    t.x = step == 1 ? xbar : VectorXd((x + step * d).cwiseMax(lower).cwiseMin(upper));
    ++out.trials;
    t.failed = !evaluate(t.x, &t.f, &t.gradient);
    if (!t.failed) t.slope = t.gradient.dot(d);
    if (t.failed || t.f > f0 + settings.c1 * step * slope0 || t.f >= lo.f) {
      hi = t;  // too long (or no value): the minimiser lies before it
      bracketed = true;
    } else {
      if (std::abs(t.slope) <= -settings.c2 * slope0) {
        accept(t, true);
        return out;
      }
      if (bracketed ? t.slope * (hi.step - lo.step) >= 0 : t.slope >= 0) {
        hi = lo;
        bracketed = true;
      }
      lo = t;
      if (!bracketed && step >= step_max) {
        accept(lo, false);  // at the box's edge, still going down
        return out;
      }
    }
    // The next trial step.
    if (bracketed) {
      const double a = std::min(lo.step, hi.step), b = std::max(lo.step, hi.step);
      const double width = b - a;
      if (width <= std::numeric_limits<double>::epsilon() * std::max(1.0, b)) break;
      double next = hi.failed ? std::nan("") : Interpolate(lo, hi);
      if (!std::isfinite(next) || next < a + 0.1 * width || next > b - 0.1 * width) {
        // Safeguard: bisect (a failed end is approached from the good side).
        next = hi.failed ? lo.step + 0.5 * (hi.step - lo.step) : 0.5 * (a + b);
      }
      step = next;
    } else {
      step = std::min(step_max, 4 * step);
    }
  }
  if (lo.step > 0) accept(lo, false);
  return out;
}

}  // namespace diffpd::solvers::lbfgsb_internal
