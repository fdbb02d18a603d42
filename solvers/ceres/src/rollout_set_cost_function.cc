#include "diffpd/solvers/ceres/rollout_set_cost_function.h"

#include "diffpd/error.h"

namespace diffpd::solvers {

RolloutSetCostFunction::RolloutSetCostFunction(RolloutSet* set) : set_(set) {
  DIFFPD_CHECK(set_ != nullptr, "RolloutSetCostFunction needs a rollout set");
  set_num_residuals(set_->num_rows());
  mutable_parameter_block_sizes()->push_back(set_->num_parameters());
}

bool RolloutSetCostFunction::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const VectorXd> p(parameters[0], set_->num_parameters());
  const bool want_jacobian = jacobians && jacobians[0];
  VectorXd values;
  MatrixXd jacobian;
  if (!set_->Evaluate(p, &values, want_jacobian ? &jacobian : nullptr)) return false;
  Eigen::Map<VectorXd>(residuals, num_residuals()) = values;
  if (want_jacobian)
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        jacobians[0], num_residuals(), set_->num_parameters()) = jacobian;
  return true;
}

}  // namespace diffpd::solvers
