// Bunny (DiffPD Sec. 7.2, initial-state optimisation with contact): a soft
// bunny (the watertight Stanford bunny OBJ from the shared data, scaled to
// 0.1 m and voxelised) is thrown onto frictional ground (plane z = 0, every
// boundary node a contact candidate). Ipopt chooses its initial velocity
// (one 3-vector shared by all nodes, |v_i| <= 3 m/s per axis) so that
//   minimise   (c_x(K) - t_x)^2 + (c_y(K) - t_y)^2     (m^2)
//   subject to c_z(k_wall) >= wall_height              (clear a wall mid-flight)
// with c the centre of mass, t = the start's centre of mass + target_offset,
// k_wall = K / 4. The bunny lands after about 0.25 s and sticks (static
// friction) and settles until K. Start: a small hop v = (0.3, 0, 1) m/s that
// clears nothing. E = 1e5 Pa, nu = 0.4, rho = 1e3 kg/m^3, h = 10 ms.
// Full: voxel 12.5 mm, 60 steps. Small: voxel 20 mm, 40 steps.
#pragma once

#include "control/trajectory_optimization.h"

namespace diffpd::problems {

struct BunnyOptions {
  Vec3 target_offset = Vec3(0.25, 0.1, 0.0);  // m, x and y used
  double wall_height = 0.10;                  // m, centre-of-mass height at state K / 4
};

class Bunny : public TrajectoryOptimizationProblem {
 public:
  explicit Bunny(BunnyOptions options = BunnyOptions()) : options_(options) {}
  std::string name() const override { return "bunny"; }
  std::string description() const override;
  Scene MakeScene(InstanceSize size) const override;
  int steps(InstanceSize size) const override { return size == InstanceSize::kSmall ? 40 : 60; }
  double time_step(InstanceSize size) const override { return 0.01; }
  Ipopt::SmartPtr<solvers::RolloutNlp> MakeNlp(const SolverOptions& options, InstanceSize size) const override;
  solvers::IpoptOptions DefaultIpoptOptions(InstanceSize size) const override;
  double improvement_margin() const override { return 0.9; }
  // The forward simulation of `diffpd run`-style tools starts with the initial guess.
  State InitialState(const Simulator& sim) const override;

 private:
  BunnyOptions options_;
};

}  // namespace diffpd::problems
