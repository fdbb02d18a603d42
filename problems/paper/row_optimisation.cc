#include "paper/row_optimisation.h"

#include "diffpd/error.h"
#include "paper/row_optimisers.h"

namespace diffpd::problems {

const char* ToString(RowOptimizer optimizer) { return optimizer == RowOptimizer::kIpopt ? "ipopt" : "lbfgsb"; }

RowOptimizer ParseRowOptimizer(const std::string& name) {
  if (name == "lbfgsb") return RowOptimizer::kLbfgsb;
  if (name == "ipopt") return RowOptimizer::kIpopt;
  throw InvalidInputError("optimizer '" + name + "' is unknown: use lbfgsb or ipopt");
}

RowOptimisationResult OptimiseRow(const PaperRow& row, const SolverOptions& options,
                                  const RowOptimisationOptions& optimisation) {
  if (optimisation.optimizer == RowOptimizer::kLbfgsb) return OptimiseRowWithLbfgsb(row, options, optimisation);
#if DIFFPD_WITH_IPOPT
  return OptimiseRowWithIpopt(row, options, optimisation);
#else
  throw InvalidInputError("optimizer ipopt: this build has no Ipopt adapter (configure with DIFFPD_WITH_IPOPT=ON)");
#endif
}

}  // namespace diffpd::problems
