// The starfish's tendon actuation: the map from the recorded tendon
// contraction (the servo command) to the activation of the four arm muscles,
// and the same map as a parameter block of a rollout function.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "diffpd/solvers/core/parameter_block.h"

namespace diffpd::problems {

// The map from the recorded tendon contraction c (servo command, m, held per
// camera frame) to the muscle activation of every simulation step:
//   servo lag:  c_f(k) = (lag c_f(k-1) + h c(k)) / (lag + h)  (first-order
//               lag, implicit Euler per step h, starting at c_f = c of the
//               window's first frame),
//   slack:      a(k) = 1 - H(c_f(k) - slack) / length, H(x) = 0 for x <= 0,
//               x^2 / (2 mm) below 1 mm, x - 0.5 mm above (a slack tendon
//               pulls nothing; the quadratic onset keeps a smooth),
//   length:     the tendon length over which the contraction is spread (the
//               fact sheet's 65 mm).
//   release:    with release_lag set, the servo follows a release (c(k) <
//               c_f(k-1)) with release_lag instead of lag (an asymmetric
//               servo: it pulls against the body, releases with it).
// slack = 0, lag = 0, length = 65 mm is the fact sheet's a = 1 - c / 65 mm
// except below 1 mm.
struct StarfishActuation {
  StarfishActuation() = default;
  StarfishActuation(double slack, double lag, double length, std::optional<double> release_lag = std::nullopt)
      : slack(slack), lag(lag), length(length), release_lag(release_lag) {}
  double slack = 0;                   // m, >= 0
  double lag = 0;                     // s, >= 0
  double length = 0.065;              // m, > 0
  std::optional<double> release_lag;  // s, >= 0; unset: lag for both directions
};

// Activations a(k) of the steps of a contraction sequence (one value per
// step, m) at time step h (s), and if not nullptr, per step the derivatives
// {da/dslack (1/m), da/dlag (1/s), da/dlength (1/m), da/drelease_lag (1/s;
// 0 without release_lag)}. Throws
// InvalidInputError for h <= 0, a negative or non-finite slack or lag, or a
// length <= 0 ("tendon lag = -1 is invalid: must be finite and >= 0 (s)",
// also "tendon release_lag = -1 ..."),
// and for a negative activation ("tendon: activation -0.2 < 0 (the filtered
// contraction exceeds slack + length: slack 0 m, length 0.01 m) at step 7").
std::vector<double> StarfishActivations(const std::vector<double>& contraction, double h,
                                        const StarfishActuation& actuation,
                                        std::vector<std::array<double, 4>>* derivatives);
// StarfishActivations with its checks of h and the actuation, but without
// the negative-activation one: *first_negative is the first step with a < 0
// (-1: none), where the sequence stops (the steps after it are not computed).
std::vector<double> StarfishActivationsUntilNegative(const std::vector<double>& contraction, double h,
                                                     const StarfishActuation& actuation,
                                                     std::vector<std::array<double, 4>>* derivatives,
                                                     int* first_negative);
// "activation -0.2 < 0 (the filtered contraction exceeds slack + length:
// slack 0 m, length 0.065 m)" of step k of `activations`.
std::string NegativeActivation(const std::vector<double>& activations, int k, const StarfishActuation& actuation);

// StarfishActivations as a parameter block {slack, lag, length} (m, s, m),
// or {slack, lag, length, release_lag} when `start` has a release_lag: it
// writes the same activation into every muscle at every step of a rollout of
// contraction.size() steps.
class TendonActuationBlock : public solvers::ParameterBlock {
 public:
  TendonActuationBlock(std::vector<double> contraction, double h, int muscles, const StarfishActuation& start);
  std::string name() const override { return "tendon_actuation"; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }
  void PushForward(const Eigen::Ref<const VectorXd>& values, int j, const solvers::RolloutSetup& setup,
                   InputDirection* direction) const override;

 private:
  std::vector<double> contraction_;
  double h_;
  int muscles_;
};

}  // namespace diffpd::problems
