#include "shared_data.h"

#include <cstdlib>
#include <filesystem>

#include "diffpd/error.h"

#ifndef DIFFPD_SHARED_DATA_DIR
#define DIFFPD_SHARED_DATA_DIR "../shared/data"
#endif

namespace diffpd::problems {

std::string SharedDataPath(const std::string& relative) {
  const char* env = std::getenv("DIFFPD_SHARED_DATA");
  const std::string dir = env && *env ? env : DIFFPD_SHARED_DATA_DIR;
  const std::string path = (std::filesystem::path(dir) / relative).string();
  if (!std::filesystem::exists(path))
    throw InvalidInputError("shared data file '" + path +
                            "' does not exist (set DIFFPD_SHARED_DATA to the shared data directory)");
  return path;
}

}  // namespace diffpd::problems
