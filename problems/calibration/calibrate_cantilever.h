// calibrate-cantilever: recover Young's modulus and Poisson's ratio of a soft
// beam from captured marker motion. It needs no file outside the repository
// (the mesh is generated, the captured motion is data/cantilever_motion.csv),
// so it is the default job of ./run.sh.
//
// The body: a 0.2 x 0.04 x 0.04 m beam of 10 x 2 x 2 hexahedra (99 nodes,
// 297 DoFs), clamped at x = 0, pd-corotated + pd-volume, under gravity
// (-9.81 m/s^2 along z). It starts at rest, twisted about its axis (the
// angle grows linearly from 0 at the clamp to pi/4 at the free end), and is
// released: it untwists (torsion, governed by the shear modulus
// E / (2 (1 + nu))) while it droops and swings (bending, governed by E), so
// both parameters show in the motion. 80 steps of 5 ms (0.4 s). Truth:
// E = 5e5 Pa, nu = 0.35, rho = 1e3 kg/m^3 (known). Six markers (the four
// corners of the free end and the two upper corners at mid-length) captured
// at 30 Hz (frames at k/30 s, k = 1..12, not aligned with the steps), with
// 0.1 mm of Gaussian noise in the shipped data/cantilever_motion.csv. Every
// fit starts from E = 2e5 Pa, nu = 0.45. The default run fits with pd-lbfgs
// alone, so that the first run is quick; `--methods pd-lbfgs,newton-cholesky`
// compares the two.
#pragma once

#include "calibration/calibrate_problem.h"

namespace diffpd::problems {

class CantileverCalibration : public CalibrationProblem {
 public:
  std::string name() const override { return "calibrate-cantilever"; }
  std::string description() const override;
  Scene MakeScene() const override;
  State InitialState(const Simulator& sim) const override;
  double default_time_step() const override { return 0.005; }

  std::string data_file() const override { return "cantilever_motion.csv"; }
  MaterialParameters truth() const override { return MaterialParameters{5e5, 0.35, 1e3}; }
  MaterialParameters initial_guess() const override { return MaterialParameters{2e5, 0.45, 1e3}; }
  std::vector<Marker> Markers(const Mesh& mesh) const override;
  std::vector<double> CaptureTimes() const override;
  double noise() const override { return 1e-4; }
  std::vector<Method> default_methods() const override { return {Method::kPdLbfgs}; }
};

}  // namespace diffpd::problems
