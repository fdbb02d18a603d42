// Central-difference checks of derivatives, with one tolerance policy.
//
// A derivative `an` (a directional derivative J d, a gradient, a Jacobian) is
// compared with central differences
//
//   fd = (f(x + h d) - f(x - h d)) / (2 h).
//
// Step. fd errs by truncation, about |f'''| h^2 / 6, and by the noise of the
// two evaluations: if each value of f is within eta * value_scale of the
// exact one, by at most eta * value_scale / h. With f changing over the size
// of its input (|f'''| ~ value_scale / input_scale^3) the two balance at
//
//   h = cbrt(eta) * input_scale / |d|_inf,
//
// i.e. the step moves x by cbrt(eta) * input_scale. eta is the noise level of
// one evaluation of f: a few units of rounding for closed forms (default
// 1e-15), the solve's relative tolerance for a value computed by an iterative
// solve (a rollout at rel_tolerance 1e-12: h = 1e-4 input_scale).
// input_scale is the input's magnitude (default |x|_inf), or the distance
// over which f changes where that is smaller: DeformationScale(F) for a
// deformation gradient (deformation.h), the element size for node positions,
// 0.5 - nu for Poisson's ratio (lambda's pole).
//
// Tolerance. Relative to the quantity's scale, floored at what the evaluation
// noise can put into fd:
//
//   |fd - an| <= rtol * max(scale, floor / rtol),   scale = |an| (or given),
//   floor = eta * value_scale / h (the noise floor, or given),
//
// i.e. |fd - an| <= max(rtol * scale, floor). Norms are 2-norms (Frobenius
// for Jacobians); a Jacobian's noise floor counts its sqrt(columns) columns.
// A test that had its own, tighter-than-policy tolerance keeps it by passing
// rtol, derivative_scale or floor explicitly.
//
// Verdict. The checks that evaluate f themselves also take differences at
// 2h and h/2 and judge them with the gradient check's verdict
// (JudgeDerivative, problems/tools/derivative_verdict.h) against the same
// tolerance: the truncation of each difference measured from the larger
// step (Richardson), its noise from the smaller one, the step of least
// uncertainty, and "pass", "fail" (a disagreement the differences resolve)
// or "unresolved" (the measured floor exceeds the tolerance) with the
// margin tolerance / max(error, measured floor).
//
// Every check returns a DifferenceCheck stating the error, the tolerance,
// the noise floor, a measured truncation estimate (Richardson: fd at 2h
// against fd at h), the verdict and the margin; Passes() turns it into a
// gtest assertion (failing on an error above the tolerance or a "fail"
// verdict) that prints all of it on failure and one line with the verdict
// and its margin for every check.
//
//   const DifferenceCheck c = CheckDirectionalDerivative(energy, x, d, grad.dot(d));
//   EXPECT_TRUE(Passes(c)) << "state " << k;
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>

#include "diffpd/types.h"

namespace diffpd::testing {

struct DifferenceOptions {
  // eta: each evaluation of f is within noise * value_scale of the exact
  // value (relative noise level; a solve's relative tolerance).
  double noise = 1e-15;
  // Pass: |fd - an| <= max(rtol * scale, floor).
  double rtol = 1e-6;
  // The input's scale (units of x, see above); <= 0: |x|_inf (1 if x = 0).
  double input_scale = 0;
  // Magnitude of f's values the noise is relative to; <= 0: the larger
  // |f(x +- h d)| (2-norm).
  double value_scale = 0;
  // The quantity's scale that rtol is relative to; <= 0: |an|.
  double derivative_scale = 0;
  // > 0: this step h instead of the rule cbrt(noise) * input_scale / |d|_inf.
  double step = 0;
  // >= 0: this absolute floor instead of the noise floor.
  double floor = -1;
  // Also evaluate f at x +- 2h to estimate the truncation error (reported
  // only, never added to the tolerance).
  bool estimate_truncation = true;
};

struct DifferenceCheck {
  double step = 0;           // h (along d, or per Jacobian column)
  double analytic = 0;       // |an|
  double numeric = 0;        // |fd|
  double error = 0;          // |fd - an|
  double scale = 0;          // the quantity's scale rtol applies to
  double rtol = 0;           // the relative tolerance applied
  double noise_floor = 0;    // eta * value_scale / h: what evaluation noise can put into fd
  double floor = 0;          // the absolute floor applied (noise_floor unless given)
  bool floor_given = false;  // the test gave its own floor (DifferenceOptions::floor)
  double tolerance = 0;      // max(rtol * scale, floor)
  // |fd(2h) - fd(h)| / 3, the truncation error of fd at h (NaN: not measured).
  double truncation = std::numeric_limits<double>::quiet_NaN();
  // The verdict from the differences at 2h, h and h/2 (at h alone, with the
  // declared noise, when only that one was taken): "pass", "fail" or
  // "unresolved"; empty when not judged (a zero tolerance).
  std::string verdict;
  double verdict_step = 0;                                           // the judged step
  double measured_floor = std::numeric_limits<double>::quiet_NaN();  // its uncertainty (absolute)
  // tolerance / max(the error at the judged step, measured_floor).
  double verdict_margin = std::numeric_limits<double>::quiet_NaN();

  bool passed() const { return error <= tolerance; }
  // tolerance / error: how many times the error fits in the tolerance (>= 1
  // passes; infinite for an exact match).
  double margin() const;
  // Passed inexactly, but with margin < 2, or (policy floor) with the noise floor
  // above rtol * scale: the differences resolve the derivative only to
  // noise_floor / scale. A test that gives its own floor has judged the
  // noise itself; only its margin is judged then.
  bool marginal() const;
  // One line with every number above and the verdict.
  std::string Describe() const;
};

// The step rule: cbrt(noise) * input_scale / direction_inf_norm.
double CentralDifferenceStep(double noise, double input_scale, double direction_inf_norm = 1.0);

// f: R^n -> R^m along d; analytic = J(x) d (m entries).
DifferenceCheck CheckDirectionalDerivative(const std::function<VectorXd(const VectorXd&)>& f, const VectorXd& x,
                                           const VectorXd& d, const VectorXd& analytic,
                                           const DifferenceOptions& options = DifferenceOptions());
// f: R^n -> R along d; analytic = grad f(x) . d.
DifferenceCheck CheckDirectionalDerivative(const std::function<double(const VectorXd&)>& f, const VectorXd& x,
                                           const VectorXd& d, double analytic,
                                           const DifferenceOptions& options = DifferenceOptions());
// The whole Jacobian (m x n), column j along the unit vector e_j.
DifferenceCheck CheckJacobian(const std::function<VectorXd(const VectorXd&)>& f, const VectorXd& x,
                              const MatrixXd& analytic, const DifferenceOptions& options = DifferenceOptions());
// The gradient (n entries) of f: R^n -> R, entry by entry.
DifferenceCheck CheckGradient(const std::function<double(const VectorXd&)>& f, const VectorXd& x,
                              const VectorXd& analytic, const DifferenceOptions& options = DifferenceOptions());

// From values the caller computed at x + h d and x - h d (e.g. two rollouts
// that give several compared quantities each); h from CentralDifferenceStep
// or the test's own. No truncation estimate; options.step is ignored.
DifferenceCheck CompareCentralDifference(const VectorXd& f_plus, const VectorXd& f_minus, double h,
                                         const VectorXd& analytic,
                                         const DifferenceOptions& options = DifferenceOptions());
DifferenceCheck CompareCentralDifference(double f_plus, double f_minus, double h, double analytic,
                                         const DifferenceOptions& options = DifferenceOptions());

// Success when check.passed() and the verdict is not "fail"; the failure
// message is check.Describe(). Every check prints "[ VERDICT ] <verdict>,
// margin <m> ..." on stdout, a marginal pass also "[ MARGINAL ]
// <Describe()>"; with the environment variable DIFFPD_PRINT_DIFFERENCE_CHECKS
// set, every check prints "[ CHECK ] <Describe()>".
::testing::AssertionResult Passes(const DifferenceCheck& check);

}  // namespace diffpd::testing
