// calibrate-bouncing-ball (after DiffPD Sec. 7.1, "Bouncing ball"): recover
// Young's modulus and Poisson's ratio of a soft ball from captured marker
// motion through an impact with frictional contact.
//
// The scene of the bouncing-ball problem (bouncing_ball.h: a sphere of
// radius 5 cm, frictional contact with the ground z = 0 for every boundary
// node, gravity, dropped from 0.1 m moving at (0.5, 0, -1) m/s) voxelised on
// a coarser 6^3 grid (fits run many rollouts), over 0.2 s in 100 steps of
// 2 ms (fall, impact, rebound). Truth: E = 5e5 Pa, nu = 0.4, rho = 1e3
// kg/m^3 (known). Six markers (the extreme vertices along +-x, +-y, +-z)
// captured at 60 Hz (frames at k/60 s, k = 1..12, not aligned with the
// steps), with 0.1 mm of Gaussian noise in the shipped
// data/bouncing_ball_motion.csv. Every fit starts from E = 2e5 Pa, nu = 0.45.
// The Jacobian holds each step's contact active set fixed (diffpd/contact.h):
// the fit follows the smooth piece of the trajectory it is on.
#pragma once

#include "scenes/bouncing_ball.h"
#include "calibration/calibrate_problem.h"

namespace diffpd::problems {

class BouncingBallCalibration : public CalibrationProblem {
 public:
  std::string name() const override { return "calibrate-bouncing-ball"; }
  std::string description() const override;
  Scene MakeScene() const override;
  State InitialState(const Simulator& sim) const override { return ball_.InitialState(sim); }
  double default_time_step() const override { return ball_.default_time_step(); }

  std::string data_file() const override { return "bouncing_ball_motion.csv"; }
  MaterialParameters truth() const override { return MaterialParameters{5e5, 0.4, 1e3}; }
  MaterialParameters initial_guess() const override { return MaterialParameters{2e5, 0.45, 1e3}; }
  std::vector<Marker> Markers(const Mesh& mesh) const override;
  std::vector<double> CaptureTimes() const override;
  double noise() const override { return 1e-4; }

 private:
  BouncingBall ball_;
};

}  // namespace diffpd::problems
