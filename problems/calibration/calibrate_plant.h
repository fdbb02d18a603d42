// calibrate-plant (after DiffPD Sec. 7.1, "Plant"): recover Young's modulus
// and Poisson's ratio of a potted plant from captured marker motion.
//
// The body: the shared plant.obj (not watertight: some edges are shared by 4
// triangles) voxelised at 1/100 of its size (cells 0.01 in OBJ units, ray
// parity), coarsened by occupancy to cells of 0.08 (a coarse cell is kept if
// any fine cell inside it is; this keeps the thin leaves connected) and
// scaled by 0.15: 135 hexahedra of 12 mm, 373 nodes (1119 DoFs), 0.144 m
// tall. The two lowest node layers (the stem in its pot) are clamped;
// pd-corotated + pd-volume. Truth: E = 3e5 Pa, nu = 0.3, rho = 1e3 kg/m^3
// (known). From the undeformed shape the plant sags under gravity while a
// gust gives it an initial velocity (0.3, 0.15, 0) m/s x (height above the
// lowest node / plant height). 30 steps of 10 ms (0.3 s).
// Five markers (the highest vertex and the extreme -x, +x, -y, +y leaf
// vertices, more than three cells above the pot) captured at 30 Hz
// (frames at k/30 s, k = 1..9, not aligned with the steps), with 0.1 mm of
// Gaussian noise in the shipped data/plant_motion.csv. Every fit starts from
// E = 1e5 Pa, nu = 0.45 (nu bounded to [0.01, 0.49], E in log space).
#pragma once

#include "calibration/calibrate_problem.h"

namespace diffpd::problems {

class PlantCalibration : public CalibrationProblem {
 public:
  std::string name() const override { return "calibrate-plant"; }
  std::string description() const override;
  Scene MakeScene() const override;
  State InitialState(const Simulator& sim) const override;
  double default_time_step() const override { return 0.01; }

  std::string data_file() const override { return "plant_motion.csv"; }
  MaterialParameters truth() const override { return MaterialParameters{3e5, 0.3, 1e3}; }
  MaterialParameters initial_guess() const override { return MaterialParameters{1e5, 0.45, 1e3}; }
  std::vector<Marker> Markers(const Mesh& mesh) const override;
  std::vector<double> CaptureTimes() const override;
  double noise() const override { return 1e-4; }

  // The plant mesh (see the file comment); throws what SharedDataPath and
  // ReadObj throw.
  static Mesh PlantMesh();
  // At rest with the velocity gust * (height above the lowest node / plant
  // height) (m/s), zero at the clamped nodes; InitialState's gust is
  // (0.3, 0.15, 0).
  static State GustState(const Simulator& sim, const Vec3& gust);
};

}  // namespace diffpd::problems
