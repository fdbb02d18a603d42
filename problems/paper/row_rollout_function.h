// A paper row as a solvers::RolloutFunction (rollout_function.h), the rollout
// core the optimiser adapters sit on: the row's scene with the row's base
// material, its base initial state and inputs, its variable blocks (shared
// with the row, bounds and starting values copied) and its loss terms as
// functionals, one row each.
//
//   PaperRow row = MakePaperRow("bunny", RowSize::kSmall);
//   row.Prepare(row.Options(Method::kPdLbfgs, 1));
//   RowRolloutFunction f = MakeRowRolloutFunction(row, row.Options(Method::kPdLbfgs, 1));
//   // f.function->Gradient(x, f.loss_rows, f.loss_weights, ...) is dL/dx
#pragma once

#include <memory>
#include <vector>

#include "diffpd/solver_options.h"
#include "diffpd/solvers/core/rollout_function.h"
#include "paper/paper_row.h"

namespace diffpd::problems {

struct RowRolloutFunction {
  std::unique_ptr<solvers::RolloutFunction> function;
  // The row of each loss term (PaperRow::loss order) and its weight:
  // L = sum_t loss_weights[t] * value of row loss_rows[t].
  std::vector<int> loss_rows;
  std::vector<double> loss_weights;
};

// Throws InvalidInputError if the row still needs PaperRow::Prepare, and what
// RolloutFunction throws for the scene or options.
RowRolloutFunction MakeRowRolloutFunction(const PaperRow& row, const SolverOptions& options);

}  // namespace diffpd::problems
