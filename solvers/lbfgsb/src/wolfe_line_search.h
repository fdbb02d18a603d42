// The line search of L-BFGS-B: a step a in (0, a_max] along a descent
// direction d = xbar - x that meets the strong Wolfe conditions
//
//   f(x + a d) <= f(x) + c1 a g^T d,   |g(x + a d)^T d| <= c2 |g^T d|,
//
// by the safeguarded cubic and quadratic interpolation of More and Thuente
// ("Line search algorithms with guaranteed sufficient decrease", ACM TOMS
// 20(3), 1994), the search of the original code (and so of scipy): while no
// step has shown both sufficient decrease and a non-negative slope it works
// on psi(a) = f(x + a d) - f(x) - c1 a g^T d; the interval of uncertainty
// [stx, sty] (stx the best step so far) is bisected when two trials have not
// shrunk it to 2/3; before a bracket the next step lies 1.1 to 4 times the
// last step's distance from stx beyond it. It ends
//   - with the strong Wolfe conditions met (strong_wolfe),
//   - at a_max with sufficient decrease and the slope still below c1 g^T d
//     (the box's edge),
//   - once the bracket is narrower than xtol times its upper end, or when
//     rounding leaves no step strictly inside it, or after max_steps trials:
//     at the best step stx if it lowered f, else without a step (the
//     original code evaluates stx again; this search keeps its value and
//     gradient).
// Every trial point is projected onto the box (a_max keeps it inside but for
// rounding); the trial at a = 1 is xbar itself, so variables that xbar puts
// on a bound land on it exactly. A failed trial evaluation shortens the step
// to halfway back to the best step (an upper end of the bracket without a
// value).
#pragma once

#include <functional>
#include <string>

#include "diffpd/types.h"

namespace diffpd::solvers::lbfgsb_internal {

// f and gradient at x; false on a failed evaluation.
using Evaluator = std::function<bool(const VectorXd& x, double* f, VectorXd* gradient)>;

struct LineSearchSettings {
  double c1 = 1e-3, c2 = 0.9;
  // Relative width of the bracket that ends the search (the original's xtol).
  double xtol = 0.1;
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
