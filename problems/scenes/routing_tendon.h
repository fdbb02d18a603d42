// A soft column bent by tendon-like muscles (after DiffPD Sec. 7.2, the
// trajectory-optimisation example "routing tendon"): a 0.03 x 0.03 x 0.12 m
// column of 3 x 3 x 12 hexahedra (208 nodes, 624 DoFs) clamped at z = 0,
// E = 1e5 Pa, nu = 0.45, rho = 1e3 kg/m^3, pd-corotated + pd-volume, gravity
// -9.81 m/s^2 along z. Four muscles with fibres along z, k = 2e5 Pa, each on
// the one-element-deep layer of one side face (muscle 0: +x, 1: -x, 2: +y,
// 3: -y; the layer excludes nothing, so corner columns belong to two
// muscles). Default inputs: muscle 0's activation ramps linearly from 1 to
// 0.8 over the rollout, the others stay at rest (1): the column bends
// toward +x. 50 steps of 10 ms.
#pragma once

#include <vector>

#include "problem.h"

namespace diffpd::problems {

class RoutingTendon : public Problem {
 public:
  std::string name() const override { return "routing-tendon"; }
  std::string description() const override;
  Scene MakeScene() const override;
  int default_steps() const override { return 50; }
  double default_time_step() const override { return 0.01; }
  std::vector<StepInput> Inputs(const Simulator& sim, int steps) const override;

  static constexpr int kMuscles = 4;
  // Nodes of the column's top face (z = 0.12 m), for tip losses.
  static std::vector<int> TipNodes(const Scene& scene);
};

}  // namespace diffpd::problems
