// Ceres' iteration table (cost, change, gradient, step, trust region, times)
// with the current values of the fitted material fields appended, one line
// per iteration on a log (e.g. stderr), flushed.
#pragma once

#include <cstdio>
#include <vector>

#include <ceres/iteration_callback.h>

#include "diffpd/solvers/core/material_block.h"

namespace diffpd::problems {

class IterationTable : public ceres::IterationCallback {
 public:
  // block: the fitted values (fitted.size() doubles), read at each
  // iteration (Ceres' update_state_every_iteration). Owns neither.
  IterationTable(FILE* log, const std::vector<solvers::MaterialField>& fitted, const double* block)
      : log_(log), fitted_(fitted), block_(block) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& s) override;

 private:
  FILE* log_;
  std::vector<solvers::MaterialField> fitted_;
  const double* block_;
};

}  // namespace diffpd::problems
