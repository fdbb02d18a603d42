// Rows of a RolloutFunction (rollout_function.h) as a Ceres cost function,
// e.g. captured-marker residuals, one residual block per capture frame:
//
//   RolloutFunction f(scene, options, num_steps);
//   f.AddBlock(std::make_unique<MaterialBlock>(...));           // {E, nu}
//   const int markers = f.AddFunctional(std::make_unique<MarkerResiduals>(...));
//   std::vector<double> material = ...;                          // the block's values
//   RolloutEvaluationCallback callback(&f, {material.data()});   // one rollout per point
//   ceres::Problem::Options po;
//   po.evaluation_callback = &callback;
//   ceres::Problem problem(po);
//   AddMarkerResidualBlocks(&problem, &f, markers, {material.data()});
//
// Parameter blocks: the function's parameter blocks, in its order, one Ceres
// parameter block each (same sizes). Residuals: the chosen rows, in order.
// All cost functions over one RolloutFunction share its cached rollout and
// Jacobian rows: with the evaluation callback the simulation runs once per
// point before Ceres evaluates the blocks; without it the first block
// evaluated at a point runs it (so a cost function is also correct alone,
// e.g. under ceres::GradientChecker).
#pragma once

#include <vector>

#include <ceres/cost_function.h>
#include <ceres/problem.h>

#include "diffpd/solvers/core/rollout_function.h"

namespace diffpd::solvers {

class RolloutCostFunction : public ceres::CostFunction {
 public:
  // Residuals: rows `rows` of `function`. Does not take ownership of
  // `function`, which must outlive this object. Throws InvalidInputError:
  //   "RolloutCostFunction: no row",
  //   "RolloutCostFunction: row 7 is out of range [0, 6)",
  //   "RolloutCostFunction: row 3 is listed twice",
  //   "RolloutCostFunction: the rollout function has no parameter block".
  RolloutCostFunction(RolloutFunction* function, std::vector<int> rows);

  // Honours the Ceres contract: jacobians == nullptr or jacobians[i] ==
  // nullptr means "not wanted"; blocks are row-major (residual-major).
  // Returns false (never throws) when the rollout or a derivative fails
  // (the reason is in the function's statistics().last_error).
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override;

  const std::vector<int>& rows() const { return rows_; }

 private:
  RolloutFunction* function_;
  std::vector<int> rows_;
};

enum class ResidualBlocks {
  kOnePerFrame,  // one residual block per capture time (sharing the rollout)
  kSingle,       // one block with every sample
};

// Adds RolloutCostFunction residual blocks (owned by the problem) for the
// rows of the MarkerResiduals functional with index `functional` of
// `function`, over `blocks` (one pointer per parameter block of the
// function, in its order), and returns their ids. Throws InvalidInputError
// if the number of blocks is not the function's ("AddMarkerResidualBlocks:
// got 2 parameter blocks, the rollout function has 1") or the functional is
// not a MarkerResiduals.
std::vector<ceres::ResidualBlockId> AddMarkerResidualBlocks(ceres::Problem* problem, RolloutFunction* function,
                                                            int functional, const std::vector<double*>& blocks,
                                                            ResidualBlocks layout = ResidualBlocks::kOnePerFrame);

}  // namespace diffpd::solvers
