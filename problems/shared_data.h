// Where the shared data (meshes, captured motion) is read from, in place.
#pragma once

#include <string>

namespace diffpd::problems {

// <dir>/<relative>, dir = the environment variable DIFFPD_SHARED_DATA if
// set, else the build's default (<source>/../shared/data). Throws
// InvalidInputError naming the path and the variable if the file does not
// exist.
std::string SharedDataPath(const std::string& relative);

}  // namespace diffpd::problems
