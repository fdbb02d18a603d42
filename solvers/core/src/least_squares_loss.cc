#include "diffpd/solvers/core/least_squares_loss.h"

#include <algorithm>

#include "diffpd/error.h"

namespace diffpd::solvers {

LeastSquaresLoss::LeastSquaresLoss(std::unique_ptr<TrajectoryFunctional> residuals) : residuals_(std::move(residuals)) {
  if (!residuals_) throw InvalidInputError("LeastSquaresLoss: the residual functional is null");
}

int LeastSquaresLoss::LastState(int num_steps) const {
  int last = 0;
  for (int i = 0; i < residuals_->num_values(); ++i) last = std::max(last, residuals_->LastStateOf(i, num_steps));
  return last;
}

double LeastSquaresLoss::Value(const Rollout& rollout) const {
  VectorXd r(residuals_->num_values());
  residuals_->Evaluate(rollout, r);
  return 0.5 * r.squaredNorm();
}

void LeastSquaresLoss::AddGradient(const Rollout& rollout, double weight, LossGradient* loss) const {
  VectorXd r(residuals_->num_values());
  residuals_->Evaluate(rollout, r);
  residuals_->AddWeightedGradient(rollout, weight * r, loss);
}

}  // namespace diffpd::solvers
