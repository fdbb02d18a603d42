// shark-control: a fish swimming by a neural-network controller, in place
// of the DiffPD paper's shark (whose scene is not public), built from the
// original water-snake template (PROBLEMS.md section 11) at the Table's
// scale.
//
// Body (metres; x head to tail, y across, z up, mid-plane z = 0), voxels of
// dx = 0.05 m whose centre lies inside:
//   trunk      0 <= x < 1.7, 0 <= y <= 0.2, |z| < hh(x): 0.075 (x < 0.1),
//              0.1 (x < 0.2), 0.15 (x < 1.4), 0.1 (x < 1.6), 0.075 (the
//              peduncle, x < 1.7);
//   tail fin   1.7 <= x < 2.0, 0.04 < y < 0.16, |z| < 0.1 + (2/3)(x - 1.7);
//   dorsal fin 0.5 <= x < 0.7, 0.04 < y < 0.16, 0.14 < z < 0.26;
// 2.0 m long, 1 324 nodes (3 972 DoFs), 832 hexes, 860 wetted quads. E = 1e6 Pa, nu = 0.45,
// rho = 1e3 kg/m^3, pd-corotated only, free, at rest, water on every
// boundary quad (the original's quad hydrodynamics). Muscles: the trunk's
// outer voxel column on each side (y < dx, y > 0.2 - dx), |z| < 0.1,
// 0.1 <= x < 1.5, as strips of single-element muscles (k = 1e5 Pa, fibres
// along x) per side and layer, root at the head: 8 strips of 28.
// Controller: the water snake's observation (the velocity of the mid-line
// node at x = 1, then positions relative to it and velocities of the 41
// mid-line nodes (x, 0.1, 0)), a 249-64-64-2 tanh network; channel 0 drives
// the lower layers (z < 0), channel 1 the upper, left strips by max(-w, 0),
// right by max(w, 0), through the delay line. Loss (the water snake's) over
// 200 steps of 3.33e-2 s: sum_k vbar_x + 10 (vbar_y^2 + vbar_z^2), vbar the
// mean velocity of the mid-line nodes; the fish swims towards -x.
//
// Small instance: the same shape at dx = 0.1 m (276 nodes, 828 DoFs, 4
// strips of 14 muscles, the water snake's 129 observed values), 40 steps.
#pragma once

#include "control/swimmer_control.h"

namespace diffpd::problems {

class SharkControl : public SwimmerControl {
 public:
  std::string name() const override { return "shark-control"; }
  std::string description() const override;
  Swimmer MakeSwimmer(bool small) const override;
  std::string reference_stem() const override { return "shark"; }
};

}  // namespace diffpd::problems
