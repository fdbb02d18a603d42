// A rollout set's Ceres cost function that counts the evaluations Ceres asks
// for (on rank 0, where the set's own statistics see only its local terms).
#pragma once

#include "diffpd/solvers/ceres/rollout_set_cost_function.h"

namespace diffpd::problems {

class CountingCostFunction : public solvers::RolloutSetCostFunction {
 public:
  // `set` and `count` are not owned and must outlive the cost function.
  CountingCostFunction(solvers::RolloutSet* set, int* count) : RolloutSetCostFunction(set), count_(count) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    ++*count_;
    return RolloutSetCostFunction::Evaluate(parameters, residuals, jacobians);
  }

 private:
  int* count_;
};

}  // namespace diffpd::problems
