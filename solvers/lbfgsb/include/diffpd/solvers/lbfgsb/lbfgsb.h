// L-BFGS-B: bound-constrained limited-memory BFGS (Byrd, Lu, Nocedal and
// Zhu, "A limited memory algorithm for bound constrained optimization",
// SIAM J. Sci. Comput. 16(5), 1995), the optimiser behind scipy's
// minimize(method='L-BFGS-B'), with scipy's defaults and stopping tests:
//
//   min_x f(x)   s.t.   lower <= x <= upper   (entries may be -+infinity)
//
// Every iteration: the generalized Cauchy point along the projected
// gradient path x(t) = P(x - t g) of the limited-memory quadratic model
// (compact representation B = theta I - W M W^T, W = [Y, theta S]); the
// model minimised over the variables still free there (the direct primal
// method; its step projected onto the box as in the code's version 3.0
// (Morales and Nocedal 2011), truncated to the box where that is no descent
// direction); a line search along d = xbar - x for a step meeting the
// strong Wolfe conditions inside the box: More and Thuente's, as the
// original code's (scipy's), with its constants (xtol 0.1), its largest step
// (to the box; 1 on the first iteration of a bounded problem) and its first
// trial (1, or 1 / |d| on the first iteration of a problem not boxed). Where
// the original ends a search by evaluating its best step again, this one
// keeps that step's value; out of trials it takes its best step if that
// lowered f (the original restarts from x). A search that finds no lower f
// restarts from steepest descent with the memory cleared, once; then the run
// stops (kLineSearchFailed).
//
//   LbfgsbResult r = MinimizeLbfgsb(
//       [](const VectorXd& x, double* f, VectorXd* g) { *f = x.squaredNorm(); *g = 2 * x; return true; },
//       x0, lower, upper);
//   // r.x, r.f, r.stop (ToString(r.stop)), r.history
//
// Failed evaluations: the objective returns false, returns a non-finite
// value or gradient entry, or throws std::exception. Nothing of such an
// evaluation is used: the line search halves its step back towards the last
// good point; a failure at the starting point stops with kStartFailed.
// Failures count as evaluations (result.failed_evaluations, last_error).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "diffpd/types.h"

namespace diffpd::solvers {

// f(x) and its gradient (x.size() entries; *gradient may need resizing).
// Returns false when it cannot evaluate at x.
using LbfgsbObjective = std::function<bool(const VectorXd& x, double* f, VectorXd* gradient)>;

// One iterate: the start (iteration 0) or the point after an iteration.
struct LbfgsbIteration {
  int iteration = 0;
  long evaluations = 0;           // objective calls so far, failed ones included
  double f = 0;                   // objective at the iterate
  double projected_gradient = 0;  // inf-norm of P(x - g) - x
  double step = 0;                // line-search step length (0 at the start)
  int free_variables = 0;         // variables free at the Cauchy point (all at the start)
};

struct LbfgsbOptions {
  // Correction pairs (s, y) kept (scipy's maxcor), >= 1.
  int memory = 10;
  // Stop when (f_k - f_k+1) / max(|f_k|, |f_k+1|, 1) <= ftol (scipy's ftol,
  // factr 1e7 times machine epsilon), >= 0.
  double ftol = 2.220446049250313e-09;
  // Stop when the projected gradient's inf-norm is <= pgtol (scipy's gtol), >= 0.
  double pgtol = 1e-5;
  // Stop after this many iterations (scipy's maxiter), >= 1.
  int max_iterations = 15000;
  // Stop after the first iteration that ends with more than this many
  // objective evaluations (scipy's maxfun; the test is made between
  // iterations, so a line search may pass it), >= 1.
  long max_evaluations = 15000;
  // Trial points per line search (scipy's maxls), >= 1.
  int max_line_search_steps = 20;
  // Strong Wolfe constants (those of the original code's line search):
  // f(x + a d) <= f(x) + sufficient_decrease a g^T d and
  // |g(x + a d)^T d| <= curvature |g^T d|; 0 < sufficient_decrease < curvature < 1.
  double sufficient_decrease = 1e-3;
  double curvature = 0.9;
  // The subspace step projected onto the box (version 3.0) rather than only
  // truncated to it (the 1995 paper).
  bool project_subspace_step = true;
  // Called at the start and after every iteration with the iterate, x and
  // the gradient there; returning false stops the run (kCallback). May be empty.
  std::function<bool(const LbfgsbIteration&, const VectorXd& x, const VectorXd& gradient)> on_iteration;

  // Throws InvalidInputError naming the field, its value and the range, e.g.
  // "L-BFGS-B options: memory = 0 is invalid: must be >= 1".
  void Validate() const;
};

// Why a run stopped.
enum class LbfgsbStop {
  kProjectedGradient,  // projected gradient inf-norm <= pgtol
  kRelativeReduction,  // relative reduction of f <= ftol
  kMaxIterations,      // max_iterations reached
  kMaxEvaluations,     // more than max_evaluations evaluations
  kLineSearchFailed,   // no acceptable step along the steepest-descent path either
  kStartFailed,        // the objective failed at the (projected) starting point
  kCallback,           // on_iteration returned false
};
// "projected gradient <= pgtol", "relative reduction <= ftol", "iteration
// limit", "evaluation limit", "line search failed", "start failed",
// "stopped by callback".
const char* ToString(LbfgsbStop stop);

struct LbfgsbResult {
  VectorXd x;         // the last iterate (within the bounds)
  double f = 0;       // f(x); NaN for kStartFailed
  VectorXd gradient;  // at x; empty for kStartFailed
  double projected_gradient = 0;
  int iterations = 0;
  long evaluations = 0;         // objective calls, failed ones included
  long failed_evaluations = 0;  // of which failed
  int memory_resets = 0;        // line searches that failed and restarted from steepest descent
  int skipped_updates = 0;      // pairs not stored (s^T y <= eps y^T y)
  LbfgsbStop stop = LbfgsbStop::kStartFailed;
  std::string last_error;                // the latest failed evaluation's reason ("" if none)
  std::vector<LbfgsbIteration> history;  // the start, then every iteration
};

// Minimises f over the box from x0 projected onto it. Throws
// InvalidInputError for invalid options, x0 empty or non-finite, bounds of
// another size than x0, a NaN bound or lower(i) > upper(i) ("lower(2) = 1 >
// upper(2) = 0: every lower bound must be <= its upper bound"). Never throws
// for a failed evaluation.
LbfgsbResult MinimizeLbfgsb(const LbfgsbObjective& objective, const VectorXd& x0, const VectorXd& lower,
                            const VectorXd& upper, const LbfgsbOptions& options = LbfgsbOptions());

}  // namespace diffpd::solvers
