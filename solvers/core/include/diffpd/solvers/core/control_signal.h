// Control signals: maps from a few coefficients c to one value per time step,
//   s_k = S(c)_k,  k = 0..K-1,  applied during step k (time t_k = k h),
// with their Jacobian ds/dc. They parameterise activations and forces over
// time (activation_block.h, external_force_block.h).
#pragma once

#include <memory>

#include "diffpd/types.h"

namespace diffpd::solvers {

class ControlSignal {
 public:
  virtual ~ControlSignal() = default;
  virtual int num_coefficients() const = 0;     // p
  int num_steps() const { return num_steps_; }  // K
  // True when s = B c for a constant K x p matrix B (then Jacobian() is B).
  virtual bool is_linear() const = 0;
  // Values s (K) at coefficients c (p); if jacobian != nullptr, also
  // ds/dc (K x p, dense). Throws InvalidInputError if c has the wrong size.
  virtual void Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const = 0;
  // The first step k whose value can depend on coefficient j (for any c);
  // K if none. Used to declare sparsity.
  virtual int FirstStep(int j) const { return 0; }
  // Coefficients whose signal is `value` at every step (e.g. a rest
  // activation of 1).
  virtual VectorXd ConstantCoefficients(double value) const = 0;

 protected:
  explicit ControlSignal(int num_steps);
  void CheckSize(const Eigen::Ref<const VectorXd>& c) const;

 private:
  int num_steps_;
};

// One free value per step: s_k = c_k (p = K).
class PerStepSignal : public ControlSignal {
 public:
  // Throws InvalidInputError unless num_steps >= 1.
  explicit PerStepSignal(int num_steps);
  int num_coefficients() const override { return num_steps(); }
  bool is_linear() const override { return true; }
  void Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const override;
  int FirstStep(int j) const override { return j; }
  VectorXd ConstantCoefficients(double value) const override;
};

// Piecewise-linear interpolation of p >= 2 knot values placed uniformly
// over the steps: knot j sits at step position j (K - 1) / (p - 1), and
// s_k = (1 - a) c_j + a c_{j+1} between knots j and j + 1. Every s_k is a
// convex combination of knots, so bounds on the knots bound every s_k.
class PiecewiseLinearSignal : public ControlSignal {
 public:
  // Throws InvalidInputError unless num_steps >= 2 and 2 <= knots <= num_steps.
  PiecewiseLinearSignal(int num_steps, int knots);
  int num_coefficients() const override { return knots_; }
  bool is_linear() const override { return true; }
  void Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const override;
  int FirstStep(int j) const override;
  VectorXd ConstantCoefficients(double value) const override;

 private:
  int knots_;
  MatrixXd basis_;  // K x p
};

// Truncated Fourier series of period T (s):
//   s(t) = c_0 + sum_{j=1..H} c_{2j-1} sin(2 pi j t / T) + c_{2j} cos(2 pi j t / T),
// p = 1 + 2 H coefficients, evaluated at t_k = k h. Linear in c: bounds on
// s_k are linear constraints on c (e.g. SignalRangeConstraints of the Ipopt adapter).
class FourierSignal : public ControlSignal {
 public:
  // Throws InvalidInputError unless num_steps >= 1, time_step > 0,
  // period > 0 (all finite) and harmonics >= 0.
  FourierSignal(int num_steps, double time_step, double period, int harmonics);
  int num_coefficients() const override { return static_cast<int>(basis_.cols()); }
  bool is_linear() const override { return true; }
  void Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const override;
  VectorXd ConstantCoefficients(double value) const override;
  // The K x p matrix B with s = B c.
  const MatrixXd& basis() const { return basis_; }

 private:
  MatrixXd basis_;
};

// A sinusoid with free offset, amplitude and phase (nonlinear in c):
//   s(t) = c_0 + c_1 sin(2 pi t / T + c_2),  t = k h.
class SinusoidSignal : public ControlSignal {
 public:
  // Throws InvalidInputError unless num_steps >= 1, time_step > 0 and
  // period > 0 (all finite).
  SinusoidSignal(int num_steps, double time_step, double period);
  int num_coefficients() const override { return 3; }
  bool is_linear() const override { return false; }
  void Evaluate(const Eigen::Ref<const VectorXd>& c, VectorXd* values, MatrixXd* jacobian) const override;
  VectorXd ConstantCoefficients(double value) const override;

 private:
  VectorXd phase_;  // 2 pi t_k / T
};

}  // namespace diffpd::solvers
