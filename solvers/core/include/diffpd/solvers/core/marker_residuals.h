// Captured-marker residuals as a trajectory functional: for each captured
// sample s (in file order) and axis d,
//   r[3 s + d] = w_sd (simulated_sd - captured_sd)   (m times the weight)
// with the simulated position interpolated in time and space
// (MarkerObservations, captured_motion.h).
#pragma once

#include <string>
#include <vector>

#include "diffpd/captured_motion.h"
#include "diffpd/mesh.h"
#include "diffpd/solvers/core/trajectory_functional.h"

namespace diffpd::solvers {

class MarkerResiduals : public TrajectoryFunctional {
 public:
  // Throws what MarkerObservations' constructor throws (invalid motion,
  // markers that do not fit the mesh, samples after num_steps steps of
  // time_step seconds).
  MarkerResiduals(const CapturedMotion& motion, const Mesh& mesh, double time_step, int num_steps);
  std::string name() const override { return "marker_residuals"; }
  int num_values() const override { return 3 * observations_.num_samples(); }
  int LastStateOf(int i, int num_steps) const override { return observations_.last_step(i / 3); }
  void Evaluate(const Rollout& rollout, Eigen::Ref<VectorXd> values) const override;
  void AddWeightedGradient(const Rollout& rollout, const Eigen::Ref<const VectorXd>& weights,
                           LossGradient* loss) const override;
  void ApplyTangents(const Rollout& rollout, const TangentRollout& tangents,
                     Eigen::Ref<MatrixXd> jacobian) const override;

  const MarkerObservations& observations() const { return observations_; }
  // Samples grouped by equal time, in order of time: one group per frame.
  std::vector<std::vector<int>> SamplesByFrame() const;

 private:
  MarkerObservations observations_;
};

}  // namespace diffpd::solvers
