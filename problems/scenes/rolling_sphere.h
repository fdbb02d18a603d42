// The paper's rolling-sphere benchmark (DiffPD Sec. 6.2), with frictional
// contact: a sphere of radius 0.05 m voxelised on a 10 x 10 x 10 grid of 1 cm
// cells (cells whose centre is inside: 823 nodes, 552 hexahedra, 2469 DoFs;
// `cells` per axis in general, of size 0.1 m / cells),
// E = 2e6 Pa, nu = 0.4, rho = 1e3 kg/m^3, pd-corotated + pd-volume, gravity
// -9.81 m/s^2 along z. The rest positions get a fixed-seed jitter (each
// coordinate uniform in [-1, 1] mm, seed 2021) and the body is then lifted so
// that its lowest node touches the plane z = 0. Frictional contact with that
// plane; candidates are the boundary nodes of the lower half (z at or below
// the centre). Initial state: rest positions, spinning at 10 rad/s about y,
// v0 = omega x (q0 - c) with c the sphere's centre. 100 steps of 5 ms. The
// active-set loop screens at relative tolerance 0.1 (contact.h): a third of
// the steps change their set, and screening cuts the PD-LBFGS iterations per
// step from 81 to 64 at rtol 1e-4.
#pragma once

#include "problem.h"

namespace diffpd::problems {

class RollingSphere : public Problem {
 public:
  // linear_solve: how PD erases the active set (Woodbury or refactorisation).
  // cells >= 1 per axis (not checked here: MakeRefinedProblem chooses it).
  explicit RollingSphere(ContactLinearSolve linear_solve = ContactLinearSolve::kWoodbury, int cells = kCells)
      : linear_solve_(linear_solve), cells_(cells) {}
  std::string name() const override { return "rolling-sphere"; }
  std::string description() const override;
  Scene MakeScene() const override;
  State InitialState(const Simulator& sim) const override;
  int default_steps() const override { return 100; }
  double default_time_step() const override { return 0.005; }

  static constexpr double kRadius = 0.05;  // m
  static constexpr double kSpin = 10.0;    // rad/s about +y
  static constexpr double kScreeningRelTolerance = 0.1;
  static constexpr int kCells = 10;  // per axis, the default grid
  // The sphere's centre (m): the midpoint of the mesh's bounding box.
  static Vec3 Center(const Scene& scene);

 private:
  ContactLinearSolve linear_solve_;
  int cells_;
};

}  // namespace diffpd::problems
