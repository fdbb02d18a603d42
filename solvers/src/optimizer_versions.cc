#include "diffpd/solvers/optimizer_versions.h"

#include <ceres/version.h>
#include <IpoptConfig.h>

namespace diffpd::solvers {

std::string OptimizerVersions() { return std::string("ceres ") + CERES_VERSION_STRING + ", ipopt " + IPOPT_VERSION; }

}  // namespace diffpd::solvers
