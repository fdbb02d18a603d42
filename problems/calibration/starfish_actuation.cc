#include "calibration/starfish_actuation.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::problems {
namespace {

constexpr double kSlackSmoothing = 0.001;  // m: width of the slack's quadratic onset

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

StarfishActuation At(const Eigen::Ref<const VectorXd>& values) {
  StarfishActuation a{values(0), values(1), values(2)};
  if (values.size() > 3) a.release_lag = values(3);
  return a;
}

}  // namespace

std::vector<double> StarfishActivationsUntilNegative(const std::vector<double>& c, double h,
                                                     const StarfishActuation& act,
                                                     std::vector<std::array<double, 4>>* derivatives,
                                                     int* first_negative) {
  if (!(std::isfinite(h) && h > 0)) throw InvalidInputError("time step = " + Num(h) + " is invalid: must be > 0 (s)");
  if (!(std::isfinite(act.slack) && act.slack >= 0))
    throw InvalidInputError("tendon slack = " + Num(act.slack) + " is invalid: must be finite and >= 0 (m)");
  if (!(std::isfinite(act.lag) && act.lag >= 0))
    throw InvalidInputError("tendon lag = " + Num(act.lag) + " is invalid: must be finite and >= 0 (s)");
  if (act.release_lag && !(std::isfinite(*act.release_lag) && *act.release_lag >= 0))
    throw InvalidInputError("tendon release_lag = " + Num(*act.release_lag) +
                            " is invalid: must be finite and >= 0 (s)");
  if (!(std::isfinite(act.length) && act.length > 0))
    throw InvalidInputError("tendon length = " + Num(act.length) + " is invalid: must be finite and > 0 (m)");
  const size_t n = c.size();
  std::vector<double> a(n);
  if (derivatives) derivatives->assign(n, {0, 0, 0, 0});
  // The filtered contraction and its derivatives in lag and release_lag.
  double f = n ? c[0] : 0, df = 0, dr = 0;
  const double w = kSlackSmoothing, L = act.length;
  for (size_t k = 0; k < n; ++k) {
    const bool release = act.release_lag && c[k] < f;
    const double lag = release ? *act.release_lag : act.lag;
    const double f_new = (lag * f + h * c[k]) / (lag + h);
    // d f_new = (lag d f + (f - f_new) d lag) / (lag + h).
    df = ((release ? 0 : f - f_new) + lag * df) / (lag + h);
    dr = ((release ? f - f_new : 0) + lag * dr) / (lag + h);
    f = f_new;
    const double x = f - act.slack;
    const double hinge = x <= 0 ? 0 : x < w ? x * x / (2 * w) : x - w / 2;
    const double slope = x <= 0 ? 0 : x < w ? x / w : 1;
    a[k] = 1 - hinge / L;
    if (a[k] < 0) {
      *first_negative = static_cast<int>(k);
      return a;
    }
    if (derivatives) (*derivatives)[k] = {slope / L, -slope * df / L, hinge / (L * L), -slope * dr / L};
  }
  *first_negative = -1;
  return a;
}

std::string NegativeActivation(const std::vector<double>& a, int k, const StarfishActuation& act) {
  return "activation " + Num(a[k]) + " < 0 (the filtered contraction exceeds slack + length: slack " + Num(act.slack) +
         " m, length " + Num(act.length) + " m)";
}

std::vector<double> StarfishActivations(const std::vector<double>& c, double h, const StarfishActuation& act,
                                        std::vector<std::array<double, 4>>* derivatives) {
  int negative = -1;
  std::vector<double> a = StarfishActivationsUntilNegative(c, h, act, derivatives, &negative);
  if (negative >= 0)
    throw InvalidInputError("tendon: " + NegativeActivation(a, negative, act) + " at step " + std::to_string(negative));
  return a;
}

TendonActuationBlock::TendonActuationBlock(std::vector<double> contraction, double h, int muscles,
                                           const StarfishActuation& start)
    : ParameterBlock(start.release_lag ? 4 : 3), contraction_(std::move(contraction)), h_(h), muscles_(muscles) {
  VectorXd initial(size());
  initial.head(3) << start.slack, start.lag, start.length;
  if (start.release_lag) initial(3) = *start.release_lag;
  SetInitial(initial);
}

void TendonActuationBlock::CheckFits(const Scene& scene, int num_steps) const {
  DIFFPD_CHECK(static_cast<int>(scene.muscles.size()) == muscles_ && static_cast<int>(contraction_.size()) == num_steps,
               "tendon actuation for " << muscles_ << " muscles over " << contraction_.size() << " steps");
}

void TendonActuationBlock::Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const {
  const std::vector<double> a = StarfishActivations(contraction_, h_, At(values), nullptr);
  for (size_t k = 0; k < a.size(); ++k) setup->inputs[k].activation = VectorXd::Constant(muscles_, a[k]);
}

void TendonActuationBlock::PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                                    Eigen::Ref<VectorXd> out) const {
  std::vector<std::array<double, 4>> d;
  StarfishActivations(contraction_, h_, At(values), &d);
  out.setZero();
  for (int j = 0; j < size(); ++j)
    for (size_t k = 0; k < d.size() && k < grad.activation.size(); ++k)
      if (grad.activation[k].size()) out(j) += grad.activation[k].dot(VectorXd::Constant(muscles_, d[k][j]));
}

void TendonActuationBlock::PushForward(const Eigen::Ref<const VectorXd>& values, int j,
                                       const solvers::RolloutSetup& setup, InputDirection* direction) const {
  std::vector<std::array<double, 4>> d;
  StarfishActivations(contraction_, h_, At(values), &d);
  for (size_t k = 0; k < d.size(); ++k) direction->activation[k] = VectorXd::Constant(muscles_, d[k][j]);
}

}  // namespace diffpd::problems
