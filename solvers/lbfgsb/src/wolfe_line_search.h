// A line search for a step a in (0, a_max] along a descent direction
// d = xbar - x that meets the strong Wolfe conditions
//
//   f(x + a d) <= f(x) + c1 a g^T d,   |g(x + a d)^T d| <= c2 |g^T d|,
//
// by bracketing and zooming with safeguarded cubic interpolation (Nocedal
// and Wright, Numerical Optimization, algorithms 3.5 and 3.6). Every trial
// point is projected onto the box (a_max keeps it inside but for rounding);
// the trial at a = 1 is xbar itself, so variables that xbar puts on a bound
// land on it exactly.
// A failed trial evaluation shortens the step towards the last good point
// (bisection). At a_max with the slope still negative the search stops there
// (the bound); out of trials it returns the best point with sufficient
// decrease, if any.
#pragma once

#include <functional>
#include <string>

#include "diffpd/types.h"

namespace diffpd::solvers::lbfgsb_internal {

// f and gradient at x; false on a failed evaluation.
using Evaluator = std::function<bool(const VectorXd& x, double* f, VectorXd* gradient)>;

struct LineSearchSettings {
  double c1 = 1e-3, c2 = 0.9;
  int max_steps = 20;
};

struct LineSearchResult {
  bool accepted = false;
  bool strong_wolfe = false;  // both conditions hold at the accepted point
  double step = 0;
  VectorXd x, gradient;  // at the accepted point
  double f = 0;
  int trials = 0;
};

LineSearchResult StrongWolfeLineSearch(const Evaluator& evaluate, const VectorXd& x, double f0, const VectorXd& g0,
                                       const VectorXd& xbar, double step0, double step_max, const VectorXd& lower,
                                       const VectorXd& upper, const LineSearchSettings& settings);

}  // namespace diffpd::solvers::lbfgsb_internal
