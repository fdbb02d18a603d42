// The paper's cantilever benchmark (DiffPD Sec. 6.2): a 0.32 x 0.08 x 0.08 m
// beam of 32 x 8 x 8 hexahedra (33 x 9 x 9 nodes, 8019 DoFs), clamped at
// x = 0, E = 1e6 Pa, nu = 0.45, rho = 1e3 kg/m^3, pd-corotated + pd-volume,
// gravity -9.81 m/s^2 along z, initially twisted about the beam axis (angle
// growing linearly from 0 at the clamp to pi/2 at the free end), at rest;
// 25 steps of 10 ms. `refinement` multiplies the cell counts (1 = paper).
#pragma once

#include "problem.h"

namespace diffpd::problems {

class Cantilever : public Problem {
 public:
  // Cells along x, y, z (default 32 x 8 x 8).
  explicit Cantilever(int nx = 32, int ny = 8, int nz = 8) : nx_(nx), ny_(ny), nz_(nz) {}
  std::string name() const override { return "cantilever"; }
  std::string description() const override;
  Scene MakeScene() const override;
  State InitialState(const Simulator& sim) const override;
  int default_steps() const override { return 25; }
  double default_time_step() const override { return 0.01; }

 private:
  int nx_, ny_, nz_;
};

// A free cube (0.1 m, 8^3 hexahedra) falling under gravity with no support,
// E = 1e5 Pa, nu = 0.4, rho = 1e3; starts at rest, slightly squashed.
class FallingCube : public Problem {
 public:
  explicit FallingCube(int cells = 8) : cells_(cells) {}
  std::string name() const override { return "falling-cube"; }
  std::string description() const override;
  Scene MakeScene() const override;
  State InitialState(const Simulator& sim) const override;
  int default_steps() const override { return 50; }
  double default_time_step() const override { return 0.01; }

 private:
  int cells_;
};

}  // namespace diffpd::problems
