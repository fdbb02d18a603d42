#include "solver/adjoint_cost_model.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace diffpd::internal {

AdjointCostModel::Solver AdjointCostModel::Leader() const {
  return estimate_[Index(Solver::kDirect)] < estimate_[Index(Solver::kIterative)] ? Solver::kDirect
                                                                                  : Solver::kIterative;
}

int AdjointCostModel::RecheckInterval() const {
  const double leader = estimate_[Index(Leader())];
  const double other = estimate_[1 - Index(Leader())];
  if (!(leader > 0)) return kMinRecheck;
  const double steps = std::ceil((other / leader - 1) / kRecheckShare);
  if (!(steps < std::numeric_limits<int>::max())) return std::numeric_limits<int>::max();
  return std::max(kMinRecheck, static_cast<int>(steps));
}

AdjointCostModel::Solver AdjointCostModel::Next() const {
  if (!measured(Solver::kIterative)) return Solver::kIterative;
  if (!measured(Solver::kDirect)) return Solver::kDirect;
  const Solver leader = Leader();
  if (leader_steps_ < RecheckInterval()) return leader;
  return leader == Solver::kDirect ? Solver::kIterative : Solver::kDirect;
}

void AdjointCostModel::Record(Solver solver, double seconds) {
  const bool both = measured(Solver::kIterative) && measured(Solver::kDirect);
  const Solver leader_before = both ? Leader() : solver;
  double& estimate = estimate_[Index(solver)];
  const bool consecutive = have_last_ && last_ == solver && measured(solver);
  estimate = consecutive ? 0.5 * (estimate + seconds) : seconds;
  measured_[Index(solver)] = true;
  have_last_ = true;
  last_ = solver;
  // The leader's steps count towards the next recheck; the other solver's
  // first measurement or recheck starts the count again.
  if (both && solver == leader_before)
    ++leader_steps_;
  else
    leader_steps_ = 0;
}

}  // namespace diffpd::internal
