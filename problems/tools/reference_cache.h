// A converged reference run kept on disk, so that repeated trade-off sweeps
// of a problem are not dominated by its reference. One JSON file per
// (problem, settings key) in a directory: <dir>/<problem>-<hash of key>.json
// holding the key itself (a file whose key differs is recomputed), the loss,
// the gradient, the final state and the seconds the reference took. The key
// names the problem's instance and the reference's settings, not the code:
// delete the directory after changing the simulator.
#pragma once

#include <functional>
#include <string>

#include "diffpd/types.h"

namespace diffpd::problems {

struct ReferenceValues {
  double loss = 0;
  VectorXd gradient;
  VectorXd state;
  double seconds = 0;  // of the run that computed it
};

// The reference stored under `dir` for (problem, key), or compute() stored
// there (the directory is created). dir empty: compute() without a cache.
// *hit (if not nullptr) says whether it came from the file. Throws
// std::runtime_error when the file cannot be written, and what compute()
// throws.
ReferenceValues CachedReference(const std::string& dir, const std::string& problem, const std::string& key,
                                const std::function<ReferenceValues()>& compute, bool* hit = nullptr);

}  // namespace diffpd::problems
