#include "diffpd/solvers/ceres/rollout_cost_function.h"

#include <sstream>

#include "diffpd/error.h"
#include "diffpd/solvers/core/marker_residuals.h"

namespace diffpd::solvers {

RolloutCostFunction::RolloutCostFunction(RolloutFunction* function, std::vector<int> rows)
    : function_(function), rows_(std::move(rows)) {
  DIFFPD_CHECK(function_ != nullptr, "RolloutCostFunction needs a rollout function");
  if (rows_.empty()) throw InvalidInputError("RolloutCostFunction: no row");
  const int num_rows = function_->num_rows();
  std::vector<char> seen(num_rows, 0);
  for (int r : rows_) {
    if (r < 0 || r >= num_rows) {
      std::ostringstream msg;
      msg << "RolloutCostFunction: row " << r << " is out of range [0, " << num_rows << ")";
      throw InvalidInputError(msg.str());
    }
    if (seen[r]++) throw InvalidInputError("RolloutCostFunction: row " + std::to_string(r) + " is listed twice");
  }
  if (function_->num_blocks() == 0)
    throw InvalidInputError("RolloutCostFunction: the rollout function has no parameter block");
  set_num_residuals(static_cast<int>(rows_.size()));
  for (int b = 0; b < function_->num_blocks(); ++b)
    mutable_parameter_block_sizes()->push_back(function_->block(b).size());
}

bool RolloutCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const int num_blocks = function_->num_blocks();
  VectorXd p(function_->num_parameters());
  bool want_jacobian = false;
  for (int b = 0; b < num_blocks; ++b) {
    const int size = function_->block(b).size();
    p.segment(function_->block_offset(b), size) = Eigen::Map<const VectorXd>(parameters[b], size);
    want_jacobian = want_jacobian || (jacobians && jacobians[b]);
  }
  VectorXd values;
  MatrixXd jacobian;
  if (!function_->Evaluate(p, rows_, &values, want_jacobian ? &jacobian : nullptr)) return false;
  Eigen::Map<VectorXd>(residuals, num_residuals()) = values;
  if (!want_jacobian) return true;
  for (int b = 0; b < num_blocks; ++b) {
    if (!jacobians[b]) continue;
    const int size = function_->block(b).size();
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        jacobians[b], num_residuals(), size) = jacobian.middleCols(function_->block_offset(b), size);
  }
  return true;
}

std::vector<ceres::ResidualBlockId> AddMarkerResidualBlocks(ceres::Problem* problem, RolloutFunction* function,
                                                            int functional, const std::vector<double*>& blocks,
                                                            ResidualBlocks layout) {
  if (static_cast<int>(blocks.size()) != function->num_blocks()) {
    std::ostringstream msg;
    msg << "AddMarkerResidualBlocks: got " << blocks.size() << " parameter blocks, the rollout function has "
        << function->num_blocks();
    throw InvalidInputError(msg.str());
  }
  if (functional < 0 || functional >= function->num_functionals())
    throw InvalidInputError("AddMarkerResidualBlocks: functional " + std::to_string(functional) +
                            " is out of range [0, " + std::to_string(function->num_functionals()) + ")");
  const auto* markers = dynamic_cast<const MarkerResiduals*>(&function->functional(functional));
  if (!markers)
    throw InvalidInputError("AddMarkerResidualBlocks: functional " + std::to_string(functional) + " ('" +
                            function->functional(functional).name() + "') is not a MarkerResiduals");
  const int first = function->functional_row(functional);
  std::vector<std::vector<int>> groups;
  if (layout == ResidualBlocks::kOnePerFrame) {
    groups = markers->SamplesByFrame();
  } else {
    groups.emplace_back();
    for (int s = 0; s < markers->observations().num_samples(); ++s) groups.back().push_back(s);
  }
  std::vector<ceres::ResidualBlockId> ids;
  for (const std::vector<int>& samples : groups) {
    std::vector<int> rows;
    for (int s : samples)
      for (int d = 0; d < 3; ++d) rows.push_back(first + 3 * s + d);
    ids.push_back(problem->AddResidualBlock(new RolloutCostFunction(function, std::move(rows)), nullptr, blocks));
  }
  return ids;
}

}  // namespace diffpd::solvers
