// Open-loop locomotion with contact and friction (DiffPD Sec. 7.3): torus,
// quadruped and cow. A soft body stands on frictional ground (plane z = 0,
// DiffPD's active-set contact: touching nodes stick, static friction) and is
// driven by muscles whose activations are periodic: one Fourier harmonic of
// period T per muscle, a_m(t) = c0 + c1 sin(2 pi t / T) + c2 cos(2 pi t / T).
// Ipopt chooses the 3 coefficients of every muscle to
//   minimise   -100 (c_x(K) - c_x(0))                 (forward travel, cm)
//   subject to 0.7 <= a_m(t_k) <= 1.3 for every muscle and step
//              (linear constraints on the coefficients: bounded activations)
//              the body's "up" axis at step K within 30 degrees of its
//              rest direction (cosine >= cos 30 deg: it must not tip over)
// c the centre of mass. Bodies (E = 1e5 Pa, nu = 0.4, rho = 1e3 kg/m^3,
// muscle stiffness 2e5 Pa, h = 10 ms, T = 0.1 s):
//  - torus: the shared torus.obj scaled to 0.1 m, a wheel standing in the
//    x-z plane; muscles = angular sectors of the ring (4 small, 8 full),
//    fibres along the ring; "up" axis = the wheel's axle (y), which must stay
//    horizontal (the wheel must not fall over);
//  - quadruped: a box body (0.12 x 0.06 x 0.03 m) on four box legs
//    (0.03 m cubes); muscles = the legs (fibres vertical), split into
//    front and back halves in the full instance; "up" = bottom -> top of the body;
//  - cow: the shared spot.obj scaled to 0.1 m long (z up, legs below
//    35 % of its height); muscles = the four legs, fibres vertical; "up"
//    as for the quadruped.
// Small: coarse voxels, 20 steps (two periods; quadruped 30), 8 Ipopt
// iterations, steps solved to rel_tolerance 1e-4 (full: 1e-6); full: finer voxels (torus and cow 12.5 mm, quadruped 15
// mm), 40 steps, 40 iterations (a full rollout takes about 10 s with newton-cholesky on one core: finer meshes are out
// of reach for now). Ipopt accepts a trial point after 3 backtracking steps (accept_after_max_steps): the contact makes
// the objective piecewise smooth, and long line searches cost a rollout each. Start: a travelling wave of amplitude
// 0.1. The objective's improvement rule: at least 0.2 cm more travel than the start.
#pragma once

#include "control/trajectory_optimization.h"

namespace diffpd::problems {

class Locomotion : public TrajectoryOptimizationProblem {
 public:
  enum class Body { kTorus, kQuadruped, kCow };
  // small_steps: steps of the small instance (-1: 30 for the quadruped,
  // whose coarse legs need three periods to get going, 20 otherwise; tests
  // shorten it).
  explicit Locomotion(Body body, int small_steps = -1)
      : body_(body),
        small_steps_(small_steps > 0            ? small_steps
                     : body == Body::kQuadruped ? 30
                                                : 20) {}
  std::string name() const override;
  std::string description() const override;
  Scene MakeScene(InstanceSize size) const override;
  int steps(InstanceSize size) const override { return size == InstanceSize::kSmall ? small_steps_ : 40; }
  double time_step(InstanceSize size) const override { return 0.01; }
  SolverOptions BaseOptions(InstanceSize size) const override;
  Ipopt::SmartPtr<solvers::RolloutNlp> MakeNlp(const SolverOptions& options, InstanceSize size) const override;
  solvers::IpoptOptions DefaultIpoptOptions(InstanceSize size) const override;
  double RequiredObjective(double initial_objective) const override { return initial_objective - 0.2; }
  std::string improvement_rule() const override { return "at least 0.2 cm more forward travel than the start"; }

  static constexpr double kPeriod = 0.1;  // s
  static constexpr double kMinActivation = 0.7;
  static constexpr double kMaxActivation = 1.3;
  static constexpr double kMaxTiltDegrees = 30.0;

 private:
  Body body_;
  int small_steps_;
};

}  // namespace diffpd::problems
