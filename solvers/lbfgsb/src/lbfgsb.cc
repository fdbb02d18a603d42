#include "diffpd/solvers/lbfgsb/lbfgsb.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

#include "cauchy_point.h"
#include "diffpd/error.h"
#include "limited_memory_matrix.h"
#include "wolfe_line_search.h"

namespace diffpd::solvers {
namespace {

using lbfgsb_internal::CauchyPoint;
using lbfgsb_internal::LimitedMemoryMatrix;

constexpr double kInf = std::numeric_limits<double>::infinity();
// The largest step considered where no bound limits it (the original code's).
constexpr double kBigStep = 1e10;

[[noreturn]] void ThrowOption(const char* field, double value, const char* range) {
  std::ostringstream msg;
  msg << "L-BFGS-B options: " << field << " = " << value << " is invalid: must be " << range;
  throw InvalidInputError(msg.str());
}

double ProjectedGradientNorm(const VectorXd& x, const VectorXd& g, const VectorXd& lower, const VectorXd& upper) {
  double norm = 0;
  for (int i = 0; i < x.size(); ++i) {
    const double p = std::clamp(x(i) - g(i), lower(i), upper(i)) - x(i);
    norm = std::max(norm, std::abs(p));
  }
  return norm;
}

// The largest a with lower <= x + a d <= upper (kBigStep if none limits it).
double MaxStepToBounds(const VectorXd& x, const VectorXd& d, const VectorXd& lower, const VectorXd& upper) {
  double step = kBigStep;
  for (int i = 0; i < x.size(); ++i) {
    if (d(i) < 0 && lower(i) > -kInf)
      step = std::min(step, std::max(0.0, (lower(i) - x(i)) / d(i)));
    else if (d(i) > 0 && upper(i) < kInf)
      step = std::min(step, std::max(0.0, (upper(i) - x(i)) / d(i)));
  }
  return step;
}

void CheckProblem(const VectorXd& x0, const VectorXd& lower, const VectorXd& upper) {
  std::ostringstream msg;
  if (x0.size() == 0) throw InvalidInputError("L-BFGS-B: x0 is empty: the problem needs at least one variable");
  if (lower.size() != x0.size() || upper.size() != x0.size()) {
    msg << "L-BFGS-B: lower has " << lower.size() << " entries and upper " << upper.size() << ", expected " << x0.size()
        << " each (the size of x0)";
    throw InvalidInputError(msg.str());
  }
  for (int i = 0; i < x0.size(); ++i) {
    if (!std::isfinite(x0(i))) {
      msg << "L-BFGS-B: x0(" << i << ") = " << x0(i) << " is invalid: must be finite";
      throw InvalidInputError(msg.str());
    }
    if (std::isnan(lower(i)) || std::isnan(upper(i))) {
      msg << "L-BFGS-B: bound " << i << " is NaN: use -inf or +inf for a missing bound";
      throw InvalidInputError(msg.str());
    }
    if (lower(i) > upper(i)) {
      msg << "L-BFGS-B: lower(" << i << ") = " << lower(i) << " > upper(" << i << ") = " << upper(i)
          << ": every lower bound must be <= its upper bound";
      throw InvalidInputError(msg.str());
    }
  }
}

}  // namespace

void LbfgsbOptions::Validate() const {
  if (memory < 1) ThrowOption("memory", memory, ">= 1");
  if (!(ftol >= 0) || !std::isfinite(ftol)) ThrowOption("ftol", ftol, "finite and >= 0");
  if (!(pgtol >= 0) || !std::isfinite(pgtol)) ThrowOption("pgtol", pgtol, "finite and >= 0");
  if (max_iterations < 1) ThrowOption("max_iterations", max_iterations, ">= 1");
  if (max_evaluations < 1) ThrowOption("max_evaluations", static_cast<double>(max_evaluations), ">= 1");
  if (max_line_search_steps < 1) ThrowOption("max_line_search_steps", max_line_search_steps, ">= 1");
  if (!(sufficient_decrease > 0 && sufficient_decrease < 1))
    ThrowOption("sufficient_decrease", sufficient_decrease, "in (0, 1)");
  if (!(curvature > sufficient_decrease && curvature < 1))
    ThrowOption("curvature", curvature, "in (sufficient_decrease, 1)");
}

const char* ToString(LbfgsbStop stop) {
  switch (stop) {
    case LbfgsbStop::kProjectedGradient:
      return "projected gradient <= pgtol";
    case LbfgsbStop::kRelativeReduction:
      return "relative reduction <= ftol";
    case LbfgsbStop::kMaxIterations:
      return "iteration limit";
    case LbfgsbStop::kMaxEvaluations:
      return "evaluation limit";
    case LbfgsbStop::kLineSearchFailed:
      return "line search failed";
    case LbfgsbStop::kStartFailed:
      return "start failed";
    case LbfgsbStop::kCallback:
      return "stopped by callback";
  }
  return "unknown";
}

LbfgsbResult MinimizeLbfgsb(const LbfgsbObjective& objective, const VectorXd& x0, const VectorXd& lower,
                            const VectorXd& upper, const LbfgsbOptions& options) {
  options.Validate();
  CheckProblem(x0, lower, upper);
  if (!objective) throw InvalidInputError("L-BFGS-B: the objective is empty");
  const int n = static_cast<int>(x0.size());

  LbfgsbResult result;
  // Every evaluation goes through here: counted, and refused (false) when it
  // fails in any way, so that nothing of it is used.
  const lbfgsb_internal::Evaluator evaluate = [&](const VectorXd& x, double* f, VectorXd* g) {
    ++result.evaluations;
    std::string error;
    bool ok = false;
    try {
      ok = objective(x, f, g);
      if (!ok)
        error = "the objective returned false";
      else if (!std::isfinite(*f))
        error = "the objective returned a non-finite value";
      else if (g->size() != n)
        error = "the objective returned a gradient of " + std::to_string(g->size()) + " entries, expected " +
                std::to_string(n);
      else if (!g->allFinite())
        error = "the objective returned a non-finite gradient entry";
    } catch (const std::exception& e) {
      error = std::string("the objective threw: ") + e.what();
    }
    if (!error.empty()) {
      ++result.failed_evaluations;
      result.last_error = error;
      return false;
    }
    return true;
  };

  bool constrained = false, boxed = true;
  for (int i = 0; i < n; ++i) {
    const bool has_lower = lower(i) > -kInf, has_upper = upper(i) < kInf;
    constrained = constrained || has_lower || has_upper;
    boxed = boxed && has_lower && has_upper;
  }

  VectorXd x = x0.cwiseMax(lower).cwiseMin(upper);
  double f = 0;
  VectorXd g;
  result.x = x;
  if (!evaluate(x, &f, &g)) {
    result.f = std::nan("");
    result.stop = LbfgsbStop::kStartFailed;
    return result;
  }
  double pg = ProjectedGradientNorm(x, g, lower, upper);
  const auto record = [&](double step, int free_variables) {
    result.x = x;
    result.f = f;
    result.gradient = g;
    result.projected_gradient = pg;
    LbfgsbIteration it;
    it.iteration = result.iterations;
    it.evaluations = result.evaluations;
    it.f = f;
    it.projected_gradient = pg;
    it.step = step;
    it.free_variables = free_variables;
    result.history.push_back(it);
    return !options.on_iteration || options.on_iteration(it, x, g);
  };
  if (!record(0, n)) {
    result.stop = LbfgsbStop::kCallback;
    return result;
  }
  if (pg <= options.pgtol) {
    result.stop = LbfgsbStop::kProjectedGradient;
    return result;
  }

  LimitedMemoryMatrix b(n, options.memory);
  lbfgsb_internal::LineSearchSettings settings;
  settings.c1 = options.sufficient_decrease;
  settings.c2 = options.curvature;
  settings.max_steps = options.max_line_search_steps;
  for (;;) {
    // The Cauchy point (skipped without bounds once there are pairs: the
    // subspace step over every variable is then the L-BFGS step from x) and
    // the subspace minimum.
    CauchyPoint cauchy;
    if (!constrained && b.pairs() > 0) {
      cauchy.x = x;
      cauchy.c = VectorXd::Zero(b.W().cols());
      for (int i = 0; i < n; ++i) cauchy.free.push_back(i);
    } else {
      cauchy = lbfgsb_internal::GeneralizedCauchyPoint(x, g, lower, upper, b);
    }
    const VectorXd xbar =
        lbfgsb_internal::SubspaceMinimum(x, g, lower, upper, cauchy, b, options.project_subspace_step);
    const VectorXd d = xbar - x;
    // The step: at most to the box (1 on the first iteration of a bounded
    // problem, as the original code), first trial 1 but on the first
    // iteration of a problem not boxed (1 / |d|).
    double step_max = kBigStep;
    if (constrained) step_max = result.iterations == 0 ? 1.0 : MaxStepToBounds(x, d, lower, upper);
    double step0 = 1;
    if (result.iterations == 0 && !boxed) step0 = std::min(1.0 / d.norm(), step_max);
    lbfgsb_internal::LineSearchResult ls;
    if (g.dot(d) < 0)
      ls = lbfgsb_internal::StrongWolfeLineSearch(evaluate, x, f, g, xbar, std::min(step0, step_max), step_max, lower,
                                                  upper, settings);
    if (!ls.accepted) {
      // No acceptable step: start again from steepest descent, or give up
      // if that is what failed.
      if (b.pairs() == 0) {
        result.stop = LbfgsbStop::kLineSearchFailed;
        return result;
      }
      b.Reset();
      ++result.memory_resets;
      continue;
    }
    const VectorXd s = ls.x - x, y = ls.gradient - g;
    const double f_old = f;
    x = ls.x;
    f = ls.f;
    g = ls.gradient;
    ++result.iterations;
    if (!b.Update(s, y)) ++result.skipped_updates;
    pg = ProjectedGradientNorm(x, g, lower, upper);
    if (!record(ls.step, static_cast<int>(cauchy.free.size()))) {
      result.stop = LbfgsbStop::kCallback;
      return result;
    }
    // scipy's order: its limits first, then the original code's tests.
    if (result.iterations >= options.max_iterations) {
      result.stop = LbfgsbStop::kMaxIterations;
      return result;
    }
    if (result.evaluations > options.max_evaluations) {
      result.stop = LbfgsbStop::kMaxEvaluations;
      return result;
    }
    if (pg <= options.pgtol) {
      result.stop = LbfgsbStop::kProjectedGradient;
      return result;
    }
    if (f_old - f <= options.ftol * std::max({std::abs(f_old), std::abs(f), 1.0})) {
      result.stop = LbfgsbStop::kRelativeReduction;
      return result;
    }
  }
}

}  // namespace diffpd::solvers
