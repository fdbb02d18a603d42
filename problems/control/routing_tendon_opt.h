// Routing tendon (DiffPD Sec. 7.3, trajectory optimisation of actuation) on
// the forward scene of routing_tendon.h: a soft 0.03 x 0.03 x 0.12 m column
// clamped at its base (z = 0) with four muscles ("tendons", fibres along z)
// on its +x, -x, +y and -y side layers. Contracting one side bends the
// column towards it. Ipopt chooses each muscle's activation over time
// (piecewise linear in time, bounded to [0.6, 1.0]; 1 = rest) so that the
// marker at the centre of the top face reaches a target:
//   minimise   |p_tip(K) - target|^2 / (1 mm)^2 + 1e-2 / 2 sum (a - 1)^2
//   subject to z_tip(k) >= z_tip(rest) - 0.01 m at k = K/2 and K
// target = rest tip + (0.02, 0.012, -0.004) m. No contact.
// Full: RoutingTendon's scene (3 x 3 x 12 cells), 30 steps of 10 ms, 6 knots.
// Small: the same column and muscle layout with 2 x 2 x 6 cells, 15 steps,
// 4 knots. The forward Problem interface (MakeScene(), default_steps(),
// Inputs()) is RoutingTendon's, so tools that simulate forward see the same
// scene; `diffpd run routing-tendon` optimises.
#pragma once

#include "control/trajectory_optimization.h"

namespace diffpd::problems {

class RoutingTendonOpt : public TrajectoryOptimizationProblem {
 public:
  std::string name() const override { return "routing-tendon"; }
  std::string description() const override;
  Scene MakeScene(InstanceSize size) const override;
  int steps(InstanceSize size) const override { return size == InstanceSize::kSmall ? 15 : 30; }
  int default_steps() const override;
  std::vector<StepInput> Inputs(const Simulator& sim, int steps) const override;
  double time_step(InstanceSize size) const override { return 0.01; }
  Ipopt::SmartPtr<solvers::RolloutNlp> MakeNlp(const SolverOptions& options, InstanceSize size) const override;
  double improvement_margin() const override { return 0.9; }
  // tol 1e-4 (the rollouts' own tolerance limits how far the optimality
  // error can fall), acceptable after 5 iterations at 1e-3.
  solvers::IpoptOptions DefaultIpoptOptions(InstanceSize size) const override;
};

}  // namespace diffpd::problems
