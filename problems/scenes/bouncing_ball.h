// A soft ball falling and bouncing on the ground (after DiffPD Sec. 7.1, the
// system-identification example): a sphere of radius 0.05 m voxelised on an
// 8 x 8 x 8 grid of 12.5 mm cells (`cells` per axis: the ball's diameter
// over the cell size; cells whose centre is inside), E = 5e5 Pa, nu = 0.4, rho = 1e3 kg/m^3,
// pd-corotated + pd-volume, gravity -9.81 m/s^2 along z, frictional contact
// with the plane z = 0 (every boundary node a candidate). It starts 0.1 m
// above the ground (lowest node) moving at (0.5, 0, -1) m/s; 150 steps of
// 2 ms (0.3 s: fall, impact, rebound).
#pragma once

#include "problem.h"

namespace diffpd::problems {

class BouncingBall : public Problem {
 public:
  // cells >= 1 (not checked here: MakeRefinedProblem chooses it).
  explicit BouncingBall(int cells = kCells) : cells_(cells) {}
  std::string name() const override { return "bouncing-ball"; }
  std::string description() const override;
  Scene MakeScene() const override;
  State InitialState(const Simulator& sim) const override;
  int default_steps() const override { return 150; }
  double default_time_step() const override { return 0.002; }

  static constexpr double kRadius = 0.05;     // m
  static constexpr double kDropHeight = 0.1;  // m, of the lowest node
  static constexpr int kCells = 8;            // per axis, the default grid

 private:
  int cells_;
};

}  // namespace diffpd::problems
