// starfish-control: the original DiffPD starfish swimming by a neural-network
// controller (DiffPD Sec. 7.4; fact sheet PROBLEMS.md section 10, read from
// the shared paper data).
//
// Scene: a plus-shaped body of 22 x 22 x 2 voxels of 0.1 m with the four
// 10 x 10 corner blocks removed (a 0.2 m central square and four arms 1.0 x
// 0.2 x 0.2 m; 387 nodes, 1161 DoFs, 168 hexes), node (11, 11, 1) at the
// origin, E = 1e6 Pa, nu = 0.45, rho = 1e3 kg/m^3, pd-corotated only, no
// gravity, no boundary, at rest; water on all 344 boundary quads (quad
// hydrodynamics with the original's curves). Muscles: 16 strips of 10
// single-element muscles (k = 1e5 Pa) along the arms' sides, root at the
// body, in pairs P0..P7 (layer z = 0 then 1):
//   P0 -y arm, x-cell 10; P1 -x arm, y-cell 10; P2 -y arm, x-cell 11;
//   P3 -x arm, y-cell 11; P4 +y arm, x-cell 10; P5 +x arm, y-cell 10;
//   P6 +y arm, x-cell 11; P7 +x arm, y-cell 11.
// Controller: the observation (243 values) of the centre node (11, 11, 1)
// and the arms' 40 mid-plane centre-line nodes, a 243-64-64-4 tanh network,
// channel c driving pairs P_{2c} and P_{2c+1} (the original's actual drive,
// with its channel-to-strip ordering quirk), layer 0 by max(-w_c, 0) and
// layer 1 by max(w_c, 0), through the delay line. Loss over 200 steps of
// 3.33e-2 s: sum_k -v_z + v_x^2 + v_y^2 of the centre node; reward = -loss.
// The original's gradient treated the centre node's position in the
// observation as a constant; here the gradient is exact.
// Masses: lumped (the body's 168 kg). The original code put rho dx^3 on every
// node (387 kg; Scene::mass_lumping = kEqualNodes reproduces it): with it the
// constant full curl of the arms swims about half as far and Adam reaches a
// lower reward on the same budget (docs/benchmarks.md, "Closed-loop control").
//
// Small instance: the same body and controller, 40 steps.
#pragma once

#include "control/swimmer_control.h"

namespace diffpd::problems {

class StarfishControl : public SwimmerControl {
 public:
  std::string name() const override { return "starfish-control"; }
  std::string description() const override;
  Swimmer MakeSwimmer(bool small) const override;
  std::string reference_stem() const override { return "starfish"; }
};

}  // namespace diffpd::problems
