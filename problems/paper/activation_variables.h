// Muscle activations (muscle.h) of the paper's rows as optimisation
// variables. Each block writes StepInput::activation of every step for the
// muscles it drives (entries of other muscles keep the base setup's value;
// an empty activation vector is first filled with 1, rest) and pulls the
// per-step activation gradient back onto its variables.
#pragma once

#include <string>
#include <vector>

#include "paper/reverse_mode_block.h"

namespace diffpd::problems {

// One activation per listed muscle, held at every step: variable j is the
// activation of muscle muscles[j] (routing tendon's 16 groups, the
// cantilever's 32 one-element muscles). dL/dx_j = sum_k dL/da_k[muscles[j]].
class ConstantActivationVariables : public ReverseModeBlock {
 public:
  // Throws InvalidInputError if muscles is empty, has a negative index or
  // num_muscles <= max index.
  ConstantActivationVariables(std::vector<int> muscles, int num_muscles);
  std::string name() const override { return "constant_activation"; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }

 private:
  std::vector<int> muscles_;
  int num_muscles_;
};

// Piecewise-linear activations on windows of `window` steps (the torus row):
// C = num_steps / window control frames of G = muscles.size() values each,
// variable c G + g the value of group g (muscle muscles[g]) at frame c. Step k
// lies in window c = floor(k / window), t = (k mod window) / window, and gets
//   a_k[g] = (1 - t) x[c G + g] + t x[c' G + g],  c' = min(c + 1, C - 1)
// (the last window is constant).
class WindowedActivationVariables : public ReverseModeBlock {
 public:
  // Throws InvalidInputError if muscles is empty or out of [0, num_muscles),
  // window < 1, or num_steps is not a positive multiple of window.
  WindowedActivationVariables(std::vector<int> muscles, int num_muscles, int num_steps, int window);
  std::string name() const override { return "windowed_activation"; }
  int num_frames() const { return num_steps_ / window_; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override;

 private:
  std::vector<int> muscles_;
  int num_muscles_, num_steps_, window_;
};

// A sinusoidal gait with three variables (A_f, A_b, w), w in rad per step
// (the quadruped and cow rows). Muscle m gets at step i = 0..K-1
//   a_i[m] = peak (1 + s_m A sin(w i)) / 2,
// s_m = +1 for a front-pulling muscle ("F"), -1 for a back one ("B"), and
// A = A_f on front legs, A_b on rear legs.
class GaitActivationVariables : public ReverseModeBlock {
 public:
  struct GaitMuscle {
    int muscle = 0;
    bool front_leg = true;  // A_f (true) or A_b
    bool forward = true;    // s_m = +1 (true) or -1
  };
  // Throws InvalidInputError if muscles is empty or out of [0, num_muscles),
  // num_steps < 1 or peak is not finite and > 0.
  GaitActivationVariables(std::vector<GaitMuscle> muscles, int num_muscles, int num_steps, double peak);
  std::string name() const override { return "gait_activation"; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }

 private:
  std::vector<GaitMuscle> muscles_;
  int num_muscles_, num_steps_;
  double peak_;
};

// An external force held at every step, one variable per DoF (3n, N; the
// cantilever and rolling-sphere rows' f). Added to the base setup's forces.
class ConstantForceVariables : public ReverseModeBlock {
 public:
  // Throws InvalidInputError unless num_dofs > 0 and a multiple of 3.
  explicit ConstantForceVariables(int num_dofs);
  std::string name() const override { return "constant_force"; }
  void CheckFits(const Scene& scene, int num_steps) const override;
  void Apply(const Eigen::Ref<const VectorXd>& values, solvers::RolloutSetup* setup) const override;
  void PullBack(const Eigen::Ref<const VectorXd>& values, const RolloutGradient& grad,
                Eigen::Ref<VectorXd> out) const override;
  int FirstAffectedState(int j) const override { return 1; }
};

}  // namespace diffpd::problems
