#include "diffpd/solvers/core/trajectory_functional.h"

namespace diffpd::solvers {

void TrajectoryFunctional::ApplyTangents(const Rollout& rollout, const TangentRollout& tangents,
                                         Eigen::Ref<MatrixXd> jacobian) const {
  const int K = rollout.num_steps();
  VectorXd unit = VectorXd::Zero(num_values());
  for (int i = 0; i < num_values(); ++i) {
    LossGradient loss(K);
    unit.setZero();
    unit(i) = 1;
    AddWeightedGradient(rollout, unit, &loss);
    jacobian.row(i).setZero();
    for (int k = 0; k <= K; ++k) {
      if (loss.dx[k].size()) jacobian.row(i).noalias() += loss.dx[k].transpose() * tangents.dx[k];
      if (loss.dv[k].size()) jacobian.row(i).noalias() += loss.dv[k].transpose() * tangents.dv[k];
    }
  }
}

}  // namespace diffpd::solvers
