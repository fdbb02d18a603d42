#include "util/central_difference.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <stdexcept>
#include <vector>

#include "tools/derivative_verdict.h"

namespace diffpd::testing {
namespace {

double InfNorm(const VectorXd& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }

double InputScale(const DifferenceOptions& options, const VectorXd& x) {
  if (options.input_scale > 0) return options.input_scale;
  const double s = InfNorm(x);
  return s > 0 ? s : 1.0;
}

double StepAlong(const DifferenceOptions& options, const VectorXd& x, const VectorXd& d) {
  if (options.step > 0) return options.step;
  return CentralDifferenceStep(options.noise, InputScale(options, x), InfNorm(d));
}

// The verdict from the compared quantities. `measured_values`: the largest
// |f| seen (the default value scale); `columns`: how many differences the
// noise enters (1 along a direction, n for a Jacobian).
DifferenceCheck Verdict(double error, double analytic, double numeric, double h, double measured_values, int columns,
                        double truncation, const DifferenceOptions& options) {
  DifferenceCheck c;
  c.step = h;
  c.error = error;
  c.analytic = analytic;
  c.numeric = numeric;
  c.rtol = options.rtol;
  c.scale = options.derivative_scale > 0 ? options.derivative_scale : analytic;
  const double value_scale = options.value_scale > 0 ? options.value_scale : measured_values;
  c.noise_floor = options.noise * value_scale / h * std::sqrt(static_cast<double>(columns));
  c.floor_given = options.floor >= 0;
  c.floor = c.floor_given ? options.floor : c.noise_floor;
  c.tolerance = std::max(options.rtol * c.scale, c.floor);
  c.truncation = truncation;
  return c;
}

std::string Format(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", v);
  return buffer;
}

std::vector<double> Entries(const MatrixXd& m) { return std::vector<double>(m.data(), m.data() + m.size()); }

// The verdict of differences `fd` at `steps` (decreasing) on `c`, judged
// against c's own absolute tolerance; `noise_at_unit_step` is the declared
// noise floor times the step.
void Judge(const std::vector<double>& steps, const std::vector<MatrixXd>& fd, const MatrixXd& analytic,
           double noise_at_unit_step, DifferenceCheck* c) {
  const double scale = std::max(analytic.norm(), fd[steps.size() > 1 ? 1 : 0].norm());
  if (!(c->tolerance > 0) || !(scale > 0)) return;
  std::vector<problems::FiniteDifferenceVector> differences;
  for (size_t k = 0; k < steps.size(); ++k)
    differences.push_back({steps[k], Entries(fd[k]), noise_at_unit_step / steps[k], 0.0});
  const problems::DerivativeJudgement j =
      problems::JudgeDerivative(Entries(analytic), differences, c->tolerance / scale);
  c->verdict = problems::ToString(j.verdict);
  c->verdict_step = j.step;
  c->measured_floor = j.floor * scale;
  c->verdict_margin = j.margin;
}

}  // namespace

double DifferenceCheck::margin() const {
  if (error == 0) return std::numeric_limits<double>::infinity();
  return tolerance / error;
}

bool DifferenceCheck::marginal() const {
  return passed() && error > 0 && (margin() < 2 || (!floor_given && noise_floor > rtol * scale));
}

std::string DifferenceCheck::Describe() const {
  std::string s = "central difference ";
  if (!passed()) {
    s += "FAILS";
  } else if (verdict == "fail") {
    s += "FAILS on the verdict of three steps";
  } else if (marginal()) {
    s += "passes marginally";
  } else {
    s += "passes";
  }
  s += " (margin " + Format(margin()) + "): |fd - an| = " + Format(error) + " vs tolerance " + Format(tolerance) +
       " = max(rtol " + Format(rtol) + " x scale " + Format(scale) + ", floor " + Format(floor) + ")";
  s += "; |an| = " + Format(analytic) + ", |fd| = " + Format(numeric) + ", h = " + Format(step) + ", noise floor " +
       Format(noise_floor);
  s += std::isnan(truncation) ? std::string(", truncation not measured") : ", truncation ~" + Format(truncation);
  if (!verdict.empty()) {
    s += "; verdict " + verdict + " (margin " + Format(verdict_margin) + " at step " + Format(verdict_step) +
         ", measured floor " + Format(measured_floor) + ")";
  }
  if (floor > rtol * scale) {
    s += floor_given ? "; the given floor sets the tolerance (" + Format(floor / scale) + " relative)"
                     : "; the noise floor sets the tolerance: the differences resolve the derivative only to " +
                           Format(floor / scale) + " relative";
  }
  if (!std::isnan(truncation) && truncation > tolerance) {
    s += "; the truncation estimate exceeds the tolerance: f is not smooth within 2h, or h is too large";
  }
  return s;
}

double CentralDifferenceStep(double noise, double input_scale, double direction_inf_norm) {
  if (!(noise > 0) || !(input_scale > 0) || !(direction_inf_norm > 0)) {
    throw std::invalid_argument("CentralDifferenceStep: noise = " + Format(noise) + ", input_scale = " +
                                Format(input_scale) + ", |d|_inf = " + Format(direction_inf_norm) + " must all be > 0");
  }
  return std::cbrt(noise) * input_scale / direction_inf_norm;
}

DifferenceCheck CheckDirectionalDerivative(const std::function<VectorXd(const VectorXd&)>& f, const VectorXd& x,
                                           const VectorXd& d, const VectorXd& analytic,
                                           const DifferenceOptions& options) {
  const double h = StepAlong(options, x, d);
  const VectorXd plus = f(x + h * d), minus = f(x - h * d);
  const VectorXd fd = (plus - minus) / (2 * h);
  double truncation = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> steps = {h};
  std::vector<MatrixXd> fds = {fd};
  if (options.estimate_truncation) {
    const VectorXd fd2 = (f(x + 2 * h * d) - f(x - 2 * h * d)) / (4 * h);
    const VectorXd half = (f(x + 0.5 * h * d) - f(x - 0.5 * h * d)) / h;
    truncation = (fd2 - fd).norm() / 3;
    steps = {2 * h, h, 0.5 * h};
    fds = {fd2, fd, half};
  }
  DifferenceCheck c = Verdict((fd - analytic).norm(), analytic.norm(), fd.norm(), h,
                              std::max(plus.norm(), minus.norm()), 1, truncation, options);
  Judge(steps, fds, analytic, c.noise_floor * h, &c);
  return c;
}

DifferenceCheck CheckDirectionalDerivative(const std::function<double(const VectorXd&)>& f, const VectorXd& x,
                                           const VectorXd& d, double analytic, const DifferenceOptions& options) {
  return CheckDirectionalDerivative([&](const VectorXd& y) { return VectorXd::Constant(1, f(y)); }, x, d,
                                    VectorXd::Constant(1, analytic), options);
}

DifferenceCheck CheckJacobian(const std::function<VectorXd(const VectorXd&)>& f, const VectorXd& x,
                              const MatrixXd& analytic, const DifferenceOptions& options) {
  const int n = static_cast<int>(x.size());
  if (analytic.cols() != n) throw std::invalid_argument("CheckJacobian: the Jacobian's columns must match x");
  const double h = options.step > 0 ? options.step : CentralDifferenceStep(options.noise, InputScale(options, x));
  MatrixXd fd(analytic.rows(), n), fd2(analytic.rows(), n), half(analytic.rows(), n);
  double values = 0;
  for (int j = 0; j < n; ++j) {
    VectorXd plus = x, minus = x;
    plus(j) += h;
    minus(j) -= h;
    const VectorXd fp = f(plus), fm = f(minus);
    values = std::max({values, fp.norm(), fm.norm()});
    fd.col(j) = (fp - fm) / (2 * h);
    if (options.estimate_truncation) {
      plus(j) += h;
      minus(j) -= h;
      fd2.col(j) = (f(plus) - f(minus)) / (4 * h);
      plus(j) = x(j) + 0.5 * h;
      minus(j) = x(j) - 0.5 * h;
      half.col(j) = (f(plus) - f(minus)) / h;
    }
  }
  const double truncation =
      options.estimate_truncation ? (fd2 - fd).norm() / 3 : std::numeric_limits<double>::quiet_NaN();
  DifferenceCheck c = Verdict((fd - analytic).norm(), analytic.norm(), fd.norm(), h, values, n, truncation, options);
  if (options.estimate_truncation)
    Judge({2 * h, h, 0.5 * h}, {fd2, fd, half}, analytic, c.noise_floor * h, &c);
  else
    Judge({h}, {fd}, analytic, c.noise_floor * h, &c);
  return c;
}

DifferenceCheck CheckGradient(const std::function<double(const VectorXd&)>& f, const VectorXd& x,
                              const VectorXd& analytic, const DifferenceOptions& options) {
  return CheckJacobian([&](const VectorXd& y) { return VectorXd::Constant(1, f(y)); }, x, analytic.transpose(),
                       options);
}

DifferenceCheck CompareCentralDifference(const VectorXd& f_plus, const VectorXd& f_minus, double h,
                                         const VectorXd& analytic, const DifferenceOptions& options) {
  const VectorXd fd = (f_plus - f_minus) / (2 * h);
  DifferenceCheck c =
      Verdict((fd - analytic).norm(), analytic.norm(), fd.norm(), h, std::max(f_plus.norm(), f_minus.norm()), 1,
              std::numeric_limits<double>::quiet_NaN(), options);
  Judge({h}, {fd}, analytic, c.noise_floor * h, &c);
  return c;
}

DifferenceCheck CompareCentralDifference(double f_plus, double f_minus, double h, double analytic,
                                         const DifferenceOptions& options) {
  return CompareCentralDifference(VectorXd::Constant(1, f_plus), VectorXd::Constant(1, f_minus), h,
                                  VectorXd::Constant(1, analytic), options);
}

::testing::AssertionResult Passes(const DifferenceCheck& check) {
  if (std::getenv("DIFFPD_PRINT_DIFFERENCE_CHECKS")) std::cout << "[ CHECK ] " << check.Describe() << std::endl;
  std::cout << "[ VERDICT ] " << (check.verdict.empty() ? std::string("not judged") : check.verdict) << ", margin "
            << Format(check.verdict_margin) << " (policy margin " << Format(check.margin()) << ", error "
            << Format(check.error) << ", measured floor " << Format(check.measured_floor) << ", tolerance "
            << Format(check.tolerance) << ")" << std::endl;
  if (!check.passed() || check.verdict == "fail") return ::testing::AssertionFailure() << check.Describe();
  if (check.marginal()) std::cout << "[ MARGINAL ] " << check.Describe() << std::endl;
  return ::testing::AssertionSuccess() << check.Describe();
}

}  // namespace diffpd::testing
