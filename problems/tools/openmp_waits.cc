#include "tools/openmp_waits.h"

#include <unistd.h>

#include <cstdlib>
#include <string>

namespace diffpd::problems {

const char* const kProgramSpinCount = "1000";

void UseShortOpenMpWaits(char** argv) {
  if (std::getenv("OMP_WAIT_POLICY") || std::getenv("GOMP_SPINCOUNT")) return;
  if (setenv("GOMP_SPINCOUNT", kProgramSpinCount, 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Not re-executed: go on with the default waits.
  unsetenv("GOMP_SPINCOUNT");
}

std::string OpenMpWaitsLabel() {
  std::string label;
  for (const char* name : {"OMP_WAIT_POLICY", "GOMP_SPINCOUNT"})
    if (const char* value = std::getenv(name)) label += (label.empty() ? "" : ", ") + std::string(name) + "=" + value;
  return label.empty() ? "OpenMP default waits" : label;
}

}  // namespace diffpd::problems
