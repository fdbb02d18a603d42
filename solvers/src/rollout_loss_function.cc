#include "diffpd/solvers/rollout_loss_function.h"

#include "diffpd/error.h"

namespace diffpd::solvers {

RolloutLossFunction::RolloutLossFunction(CalibrationModel* model, TrajectoryLoss loss)
    : model_(model), loss_(std::move(loss)) {
  DIFFPD_CHECK(model_ != nullptr, "RolloutLossFunction needs a model");
  for (int size : model_->parameter_block_sizes()) num_parameters_ += size;
}

bool RolloutLossFunction::Evaluate(const double* parameters, double* cost, double* gradient) const {
  std::vector<const double*> blocks;
  for (int size : model_->parameter_block_sizes()) {
    blocks.push_back(parameters);
    parameters += size;
  }
  return model_->EvaluateLoss(blocks.data(), loss_, cost, gradient);
}

}  // namespace diffpd::solvers
