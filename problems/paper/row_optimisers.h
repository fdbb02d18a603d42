// The two optimisers behind OptimiseRow (row_optimisation.h), one file each.
#pragma once

#include "paper/row_optimisation.h"

namespace diffpd::problems {

RowOptimisationResult OptimiseRowWithLbfgsb(const PaperRow& row, const SolverOptions& options,
                                            const RowOptimisationOptions& optimisation);
// Compiled with the Ipopt adapter only.
RowOptimisationResult OptimiseRowWithIpopt(const PaperRow& row, const SolverOptions& options,
                                           const RowOptimisationOptions& optimisation);

}  // namespace diffpd::problems
