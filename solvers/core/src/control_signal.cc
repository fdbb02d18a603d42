#include "diffpd/solvers/core/control_signal.h"

#include <cmath>
#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {
namespace {

void RequirePositiveFinite(double value, const char* name) {
  if (!(std::isfinite(value) && value > 0)) {
    std::ostringstream msg;
    msg << name << " = " << value << " is invalid: must be finite and > 0 (s)";
    throw InvalidInputError(msg.str());
  }
}

void RequireSteps(int num_steps, int minimum) {
  if (num_steps < minimum) {
    std::ostringstream msg;
    msg << "num_steps = " << num_steps << " is invalid: a control signal needs at least " << minimum << " step(s)";
    throw InvalidInputError(msg.str());
  }
}

void Linear(const MatrixXd& basis, const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) {
  if (values) *values = basis * c;
  if (jacobian) *jacobian = basis;
}

}  // namespace

ControlSignal::ControlSignal(int num_steps) : num_steps_(num_steps) { RequireSteps(num_steps, 1); }

void ControlSignal::CheckSize(const Eigen::Ref<const VectorXd>& c) const {
  if (c.size() != num_coefficients()) {
    std::ostringstream msg;
    msg << "control signal coefficients have " << c.size() << " entries, expected " << num_coefficients();
    throw InvalidInputError(msg.str());
  }
}

PerStepSignal::PerStepSignal(int num_steps) : ControlSignal(num_steps) {}

void PerStepSignal::Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const {
  CheckSize(c);
  if (values) *values = c;
  if (jacobian) *jacobian = MatrixXd::Identity(num_steps(), num_steps());
}

VectorXd PerStepSignal::ConstantCoefficients(double value) const { return VectorXd::Constant(num_steps(), value); }

PiecewiseLinearSignal::PiecewiseLinearSignal(int num_steps, int knots) : ControlSignal(num_steps), knots_(knots) {
  RequireSteps(num_steps, 2);
  if (knots < 2 || knots > num_steps) {
    std::ostringstream msg;
    msg << "knots = " << knots << " is invalid: must be in [2, num_steps = " << num_steps << "]";
    throw InvalidInputError(msg.str());
  }
  basis_ = MatrixXd::Zero(num_steps, knots);
  const double spacing = double(num_steps - 1) / (knots - 1);  // steps between knots
  for (int k = 0; k < num_steps; ++k) {
    const double position = k / spacing;
    const int j = std::min(static_cast<int>(std::floor(position)), knots - 2);
    const double a = position - j;
    basis_(k, j) = 1 - a;
    basis_(k, j + 1) += a;
  }
}

void PiecewiseLinearSignal::Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const {
  CheckSize(c);
  Linear(basis_, c, values, jacobian);
}

int PiecewiseLinearSignal::FirstStep(int j) const {
  for (int k = 0; k < num_steps(); ++k)
    if (basis_(k, j) != 0) return k;
  return num_steps();
}

VectorXd PiecewiseLinearSignal::ConstantCoefficients(double value) const { return VectorXd::Constant(knots_, value); }

FourierSignal::FourierSignal(int num_steps, double time_step, double period, int harmonics) : ControlSignal(num_steps) {
  RequirePositiveFinite(time_step, "time_step");
  RequirePositiveFinite(period, "period");
  if (harmonics < 0) {
    std::ostringstream msg;
    msg << "harmonics = " << harmonics << " is invalid: must be >= 0";
    throw InvalidInputError(msg.str());
  }
  basis_.resize(num_steps, 1 + 2 * harmonics);
  for (int k = 0; k < num_steps; ++k) {
    const double omega_t = 2 * M_PI * k * time_step / period;
    basis_(k, 0) = 1;
    for (int j = 1; j <= harmonics; ++j) {
      basis_(k, 2 * j - 1) = std::sin(j * omega_t);
      basis_(k, 2 * j) = std::cos(j * omega_t);
    }
  }
}

void FourierSignal::Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const {
  CheckSize(c);
  Linear(basis_, c, values, jacobian);
}

VectorXd FourierSignal::ConstantCoefficients(double value) const {
  VectorXd c = VectorXd::Zero(num_coefficients());
  c(0) = value;
  return c;
}

SinusoidSignal::SinusoidSignal(int num_steps, double time_step, double period) : ControlSignal(num_steps) {
  RequirePositiveFinite(time_step, "time_step");
  RequirePositiveFinite(period, "period");
  phase_.resize(num_steps);
  for (int k = 0; k < num_steps; ++k) phase_(k) = 2 * M_PI * k * time_step / period;
}

void SinusoidSignal::Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const {
  CheckSize(c);
  const Eigen::ArrayXd angle = phase_.array() + c(2);
  if (values) *values = (c(0) + c(1) * angle.sin()).matrix();
  if (jacobian) {
    jacobian->resize(num_steps(), 3);
    jacobian->col(0).setOnes();
    jacobian->col(1) = angle.sin().matrix();
    jacobian->col(2) = (c(1) * angle.cos()).matrix();
  }
}

VectorXd SinusoidSignal::ConstantCoefficients(double value) const { return Eigen::Vector3d(value, 0, 0); }

}  // namespace diffpd::solvers
