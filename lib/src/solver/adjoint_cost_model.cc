#include "solver/adjoint_cost_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace diffpd::internal {

int AdjointCostModel::RecheckInterval() const {
  if (!(direct_estimate_ > 0)) return kMinRecheck;
  const double steps = std::ceil((iteration_estimate_ / direct_estimate_ - 1) / kRecheckShare);
  if (!(steps < std::numeric_limits<int>::max())) return std::numeric_limits<int>::max();
  return std::max(kMinRecheck, static_cast<int>(steps));
}

bool AdjointCostModel::DirectLeads() const {
  return measured_iteration_ && direct_estimate_ > 0 && direct_estimate_ * (1 + kDirectMargin) < iteration_estimate_;
}

AdjointCostModel::Solver AdjointCostModel::Next() const {
  if (!DirectLeads()) return Solver::kIterative;
  return direct_steps_ < RecheckInterval() ? Solver::kDirect : Solver::kIterative;
}

void AdjointCostModel::Record(Solver solver, double seconds) {
  if (solver == Solver::kDirect) {
    ++direct_steps_;
    last_iterative_ = false;
    return;
  }
  iteration_estimate_ = last_iterative_ && measured_iteration_ ? 0.5 * (iteration_estimate_ + seconds) : seconds;
  measured_iteration_ = true;
  last_iterative_ = true;
  direct_steps_ = 0;
}

}  // namespace diffpd::internal
