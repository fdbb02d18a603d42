#include "diffpd/solvers/core/marker_residuals.h"

#include <map>

namespace diffpd::solvers {

MarkerResiduals::MarkerResiduals(const CapturedMotion& motion, const Mesh& mesh, double time_step, int num_steps)
    : observations_(motion, mesh, time_step, num_steps) {}

void MarkerResiduals::Evaluate(const Rollout& rollout, Eigen::Ref<VectorXd> values) const {
  values = observations_.Residuals(rollout.states);
}

void MarkerResiduals::AddWeightedGradient(const Rollout& rollout, const Eigen::Ref<const VectorXd>& weights,
                                          LossGradient* loss) const {
  const Eigen::Index n = rollout.states.front().x.size();
  for (int s = 0; s < observations_.num_samples(); ++s) {
    const Vec3 c = observations_.weight(s).cwiseProduct(weights.segment<3>(3 * s));
    if (c.isZero(0)) continue;
    for (const MarkerObservations::Term& term : observations_.terms(s)) {
      VectorXd& dx = loss->dx[term.step];
      if (dx.size() == 0) dx = VectorXd::Zero(n);
      dx.segment<3>(3 * term.node) += term.weight * c;
    }
  }
}

void MarkerResiduals::ApplyTangents(const Rollout& rollout, const TangentRollout& tangents,
                                    Eigen::Ref<MatrixXd> jacobian) const {
  jacobian.setZero();
  for (int s = 0; s < observations_.num_samples(); ++s) {
    for (const MarkerObservations::Term& term : observations_.terms(s))
      jacobian.middleRows<3>(3 * s) += term.weight * tangents.dx[term.step].middleRows<3>(3 * term.node);
    jacobian.middleRows<3>(3 * s) = observations_.weight(s).asDiagonal() * jacobian.middleRows<3>(3 * s);
  }
}

std::vector<std::vector<int>> MarkerResiduals::SamplesByFrame() const {
  std::map<double, std::vector<int>> frames;
  for (int s = 0; s < observations_.num_samples(); ++s) frames[observations_.time(s)].push_back(s);
  std::vector<std::vector<int>> out;
  for (auto& kv : frames) out.push_back(std::move(kv.second));
  return out;
}

}  // namespace diffpd::solvers
