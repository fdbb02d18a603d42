#include "wolfe_line_search.h"

#include <algorithm>
#include <cmath>

namespace diffpd::solvers::lbfgsb_internal {
namespace {

// A step with its value and slope g(x + a d)^T d (of f or of psi).
struct Point {
  double step = 0, f = 0, slope = 0;
  bool has_value = true;  // false: its evaluation failed (an upper end only)
};

// The minimiser of the cubic interpolating (a, fa, da) and (b, fb, db),
// written as in More and Thuente with gamma's sign taken towards `toward`
// (the scaling by s guards against overflow); the cubic may have no
// minimiser, then the root is clamped at 0 (clamp_root) or the formula gives
// the one of the quadratic limit.
struct CubicTerms {
  double theta, gamma;
};
CubicTerms Cubic(const Point& a, const Point& b, bool clamp_root) {
  const double theta = 3 * (a.f - b.f) / (b.step - a.step) + a.slope + b.slope;
  const double s = std::max({std::abs(theta), std::abs(a.slope), std::abs(b.slope)});
  double radicand = (theta / s) * (theta / s) - (a.slope / s) * (b.slope / s);
  if (clamp_root || radicand < 0) radicand = std::max(radicand, 0.0);
  return {theta, s * std::sqrt(radicand)};
}

// More and Thuente's safeguarded step from the best step x, the other end y
// and the trial t, within [step_min, step_max] while nothing is bracketed;
// updates x and y (the interval of uncertainty) and bracketed.
double SafeguardedStep(Point* x, Point* y, const Point& t, bool* bracketed, double step_min, double step_max) {
  const double sign = x->slope < 0 ? -t.slope : t.slope;  // < 0: the slopes differ in sign
  double next;
  if (t.f > x->f) {
    // Case 1, a higher value: the minimiser is bracketed. The cubic step if
    // it is the nearer to x, else halfway between it and the quadratic's.
    CubicTerms c = Cubic(*x, t, false);
    if (t.step < x->step) c.gamma = -c.gamma;
    const double p = (c.gamma - x->slope) + c.theta;
    const double q = ((c.gamma - x->slope) + c.gamma) + t.slope;
    const double cubic = x->step + (p / q) * (t.step - x->step);
    const double quadratic =
        x->step + ((x->slope / ((x->f - t.f) / (t.step - x->step) + x->slope)) / 2) * (t.step - x->step);
    next = std::abs(cubic - x->step) < std::abs(quadratic - x->step) ? cubic : cubic + (quadratic - cubic) / 2;
    *bracketed = true;
  } else if (sign < 0) {
    // Case 2, a lower value and the slope's sign changed: bracketed. The
    // cubic step if it is the farther from t, else the secant step.
    CubicTerms c = Cubic(*x, t, false);
    if (t.step > x->step) c.gamma = -c.gamma;
    const double p = (c.gamma - t.slope) + c.theta;
    const double q = ((c.gamma - t.slope) + c.gamma) + x->slope;
    const double cubic = t.step + (p / q) * (x->step - t.step);
    const double secant = t.step + (t.slope / (t.slope - x->slope)) * (x->step - t.step);
    next = std::abs(cubic - t.step) > std::abs(secant - t.step) ? cubic : secant;
    *bracketed = true;
  } else if (std::abs(t.slope) < std::abs(x->slope)) {
    // Case 3, a lower value, the same sign and a smaller slope: the cubic
    // step only if the cubic tends to infinity in the step's direction (and
    // its minimum is beyond t), else the interval's end.
    CubicTerms c = Cubic(*x, t, true);
    if (t.step > x->step) c.gamma = -c.gamma;
    const double p = (c.gamma - t.slope) + c.theta;
    const double q = (c.gamma + (x->slope - t.slope)) + c.gamma;
    const double r = p / q;
    double cubic;
    if (r < 0 && c.gamma != 0)
      cubic = t.step + r * (x->step - t.step);
    else
      cubic = t.step > x->step ? step_max : step_min;
    const double secant = t.step + (t.slope / (t.slope - x->slope)) * (x->step - t.step);
    if (*bracketed) {
      // The nearer of the two, at most 0.66 of the way to y.
      next = std::abs(cubic - t.step) < std::abs(secant - t.step) ? cubic : secant;
      const double limit = t.step + 0.66 * (y->step - t.step);
      next = t.step > x->step ? std::min(limit, next) : std::max(limit, next);
    } else {
      next = std::abs(cubic - t.step) > std::abs(secant - t.step) ? cubic : secant;
      next = std::clamp(next, step_min, step_max);
    }
  } else {
    // Case 4, a lower value, the same sign and no smaller slope: the cubic
    // through t and y if bracketed (halfway to y if y has no value), else
    // the interval's end.
    if (*bracketed && y->has_value) {
      CubicTerms c = Cubic(t, *y, false);
      if (t.step > y->step) c.gamma = -c.gamma;
      const double p = (c.gamma - t.slope) + c.theta;
      const double q = ((c.gamma - t.slope) + c.gamma) + y->slope;
      next = t.step + (p / q) * (y->step - t.step);
    } else if (*bracketed) {
      next = t.step + 0.5 * (y->step - t.step);
    } else {
      next = t.step > x->step ? step_max : step_min;
    }
  }
  // The interval of uncertainty.
  if (t.f > x->f) {
    *y = t;
  } else {
    if (sign < 0) *y = *x;
    *x = t;
  }
  return next;
}

}  // namespace

LineSearchResult StrongWolfeLineSearch(const Evaluator& evaluate, const VectorXd& x, double f0, const VectorXd& g0,
                                       const VectorXd& xbar, double step0, double step_max, const VectorXd& lower,
                                       const VectorXd& upper, const LineSearchSettings& settings) {
  LineSearchResult out;
  const VectorXd d = xbar - x;
  const double slope0 = g0.dot(d);
  if (!(slope0 < 0) || !(step_max > 0)) return out;
  constexpr double kExtrapolateMin = 1.1, kExtrapolateMax = 4;
  const double decrease_slope = settings.c1 * slope0;  // psi(a) = f(a) - f0 - a decrease_slope

  Point best{0, f0, slope0}, other{0, f0, slope0};  // stx and sty
  VectorXd best_x = x, best_gradient = g0;
  bool bracketed = false, first_stage = true;
  double step = std::min(step0, step_max);
  double width = step_max, previous_width = 2 * width;
  double low = 0, high = step + kExtrapolateMax * step;  // where the next step may fall
  const auto finish = [&](const Point& p, const VectorXd& px, const VectorXd& pg, bool wolfe) {
    out.accepted = true;
    out.strong_wolfe = wolfe;
    out.step = p.step;
    out.x = px;
    out.gradient = pg;
    out.f = p.f;
    return out;
  };
  // Ends without the Wolfe conditions: at the best step if it lowered f.
  const auto give_up = [&]() {
    if (best.step > 0 && best.f < f0) return finish(best, best_x, best_gradient, false);
    return out;
  };
  for (int k = 0; k < settings.max_steps; ++k) {
    Point t;
    t.step = step;
    const VectorXd xt = step == 1 ? xbar : VectorXd((x + step * d).cwiseMax(lower).cwiseMin(upper));
    VectorXd gt;
    ++out.trials;
    t.has_value = evaluate(xt, &t.f, &gt);
    double next;
    if (!t.has_value) {
      // Too long (or no value): halfway back to the best step.
      other = t;
      bracketed = true;
      next = best.step + 0.5 * (step - best.step);
    } else {
      t.slope = gt.dot(d);
      const double sufficient = f0 + step * decrease_slope;
      if (first_stage && t.f <= sufficient && t.slope >= 0) first_stage = false;
      if (t.f <= sufficient && std::abs(t.slope) <= -settings.c2 * slope0) return finish(t, xt, gt, true);
      if (step == step_max && t.f <= sufficient && t.slope <= decrease_slope)
        return finish(t, xt, gt, false);  // at the box's edge, still going down
      const Point old_best = best;
      if (first_stage && t.f <= best.f && t.f > sufficient) {
        // On psi, whose minimisers have sufficient decrease.
        const auto modified = [&](Point p) {
          if (p.has_value) {
            p.f -= p.step * decrease_slope;
            p.slope -= decrease_slope;
          }
          return p;
        };
        const auto restored = [&](Point p) {
          if (p.has_value) {
            p.f += p.step * decrease_slope;
            p.slope += decrease_slope;
          }
          return p;
        };
        Point mb = modified(best), mo = modified(other);
        next = SafeguardedStep(&mb, &mo, modified(t), &bracketed, low, high);
        best = restored(mb);
        other = restored(mo);
      } else {
        next = SafeguardedStep(&best, &other, t, &bracketed, low, high);
      }
      if (best.step != old_best.step) {
        best_x = xt;
        best_gradient = gt;
      }
    }
    if (bracketed) {
      // Bisect when two steps have not shrunk the interval to 2/3.
      if (std::abs(other.step - best.step) >= 0.66 * previous_width) next = best.step + 0.5 * (other.step - best.step);
      previous_width = width;
      width = std::abs(other.step - best.step);
      low = std::min(best.step, other.step);
      high = std::max(best.step, other.step);
    } else {
      low = next + kExtrapolateMin * (next - best.step);
      high = next + kExtrapolateMax * (next - best.step);
    }
    step = std::clamp(next, 0.0, step_max);
    // No further progress: the step would leave the bracket (rounding) or
    // the bracket is narrow relative to its scale.
    if (bracketed && (step <= low || step >= high || high - low <= settings.xtol * high)) return give_up();
    if (!std::isfinite(step)) return give_up();
  }
  return give_up();
}

}  // namespace diffpd::solvers::lbfgsb_internal
