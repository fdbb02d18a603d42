#include "diffpd/solvers/marker_cost_function.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {

MarkerCostFunction::MarkerCostFunction(CalibrationModel* model, std::vector<int> samples)
    : model_(model), samples_(std::move(samples)) {
  DIFFPD_CHECK(model_ != nullptr, "MarkerCostFunction needs a model");
  const int num_samples = model_->observations().num_samples();
  if (samples_.empty())
    for (int s = 0; s < num_samples; ++s) samples_.push_back(s);
  std::vector<char> seen(num_samples, 0);
  for (int s : samples_) {
    if (s < 0 || s >= num_samples) {
      std::ostringstream msg;
      msg << "MarkerCostFunction: sample " << s << " is out of range (the model has " << num_samples << " samples)";
      throw InvalidInputError(msg.str());
    }
    if (seen[s]++) throw InvalidInputError("MarkerCostFunction: sample " + std::to_string(s) + " is listed twice");
  }
  set_num_residuals(3 * static_cast<int>(samples_.size()));
  for (int size : model_->parameter_block_sizes()) mutable_parameter_block_sizes()->push_back(size);
}

bool MarkerCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  bool want_jacobian = false;
  const int num_blocks = static_cast<int>(parameter_block_sizes().size());
  for (int b = 0; jacobians && b < num_blocks; ++b) want_jacobian = want_jacobian || jacobians[b] != nullptr;
  if (!model_->Evaluate(parameters, want_jacobian)) return false;
  const VectorXd& r = model_->residuals();
  const int rows = num_residuals();
  for (size_t i = 0; i < samples_.size(); ++i)
    for (int d = 0; d < 3; ++d) residuals[3 * i + d] = r(3 * samples_[i] + d);
  if (!want_jacobian) return true;
  for (int b = 0; b < num_blocks; ++b) {
    if (!jacobians[b]) continue;
    const MatrixXd& j = model_->jacobian(b);
    const int cols = parameter_block_sizes()[b];
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> out(jacobians[b], rows, cols);
    for (size_t i = 0; i < samples_.size(); ++i) out.middleRows<3>(3 * i) = j.middleRows<3>(3 * samples_[i]);
  }
  return true;
}

RolloutEvaluationCallback::RolloutEvaluationCallback(CalibrationModel* model, std::vector<double*> blocks)
    : model_(model), blocks_(std::move(blocks)) {
  DIFFPD_CHECK(model_ != nullptr, "RolloutEvaluationCallback needs a model");
  if (blocks_.size() != model_->parameter_block_sizes().size()) {
    std::ostringstream msg;
    msg << "RolloutEvaluationCallback: got " << blocks_.size() << " parameter blocks, the model has "
        << model_->parameter_block_sizes().size();
    throw InvalidInputError(msg.str());
  }
}

void RolloutEvaluationCallback::PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) {
  model_->Evaluate(blocks_.data(), evaluate_jacobians);  // failures surface in the cost functions
}

std::vector<ceres::ResidualBlockId> AddMarkerResidualBlocks(ceres::Problem* problem, CalibrationModel* model,
                                                            const std::vector<double*>& blocks, ResidualBlocks layout) {
  if (blocks.size() != model->parameter_block_sizes().size()) {
    std::ostringstream msg;
    msg << "AddMarkerResidualBlocks: got " << blocks.size() << " parameter blocks, the model has "
        << model->parameter_block_sizes().size();
    throw InvalidInputError(msg.str());
  }
  std::vector<std::vector<int>> groups;
  if (layout == ResidualBlocks::kOnePerFrame)
    groups = model->SamplesByFrame();
  else
    groups.emplace_back();  // empty: all samples
  std::vector<ceres::ResidualBlockId> ids;
  for (auto& g : groups)
    ids.push_back(problem->AddResidualBlock(new MarkerCostFunction(model, std::move(g)), nullptr, blocks));
  return ids;
}

}  // namespace diffpd::solvers
