// Versions of the optimiser libraries the adapters were built against.
#pragma once

#include <string>

namespace diffpd::solvers {

// "ceres <major>.<minor>.<patch>, ipopt <version>" as seen at compile time.
std::string OptimizerVersions();

}  // namespace diffpd::solvers
