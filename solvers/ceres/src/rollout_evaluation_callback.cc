#include "diffpd/solvers/ceres/rollout_evaluation_callback.h"

#include <sstream>

#include "diffpd/error.h"

namespace diffpd::solvers {

RolloutEvaluationCallback::RolloutEvaluationCallback(RolloutFunction* function, std::vector<double*> blocks,
                                                     std::vector<int> rows)
    : function_(function), blocks_(std::move(blocks)), rows_(std::move(rows)) {
  DIFFPD_CHECK(function_ != nullptr, "RolloutEvaluationCallback needs a rollout function");
  if (static_cast<int>(blocks_.size()) != function_->num_blocks()) {
    std::ostringstream msg;
    msg << "RolloutEvaluationCallback: got " << blocks_.size() << " parameter blocks, the rollout function has "
        << function_->num_blocks();
    throw InvalidInputError(msg.str());
  }
  if (rows_.empty()) rows_ = function_->AllRows();
}

void RolloutEvaluationCallback::PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) {
  VectorXd p(function_->num_parameters());
  for (int b = 0; b < function_->num_blocks(); ++b) {
    const int size = function_->block(b).size();
    p.segment(function_->block_offset(b), size) = Eigen::Map<const VectorXd>(blocks_[b], size);
  }
  // Failures surface in the cost functions.
  function_->Evaluate(p, rows_, nullptr, evaluate_jacobians ? &scratch_ : nullptr);
}

}  // namespace diffpd::solvers
