// Opening the files the library reads, with one message per failure.
#pragma once

#include <cstdint>
#include <fstream>
#include <string>

namespace diffpd {

// Opens `path` for reading. Throws InvalidInputError
//   "cannot open '<path>': it is a directory, not a file" or
//   "cannot open '<path>'" (missing, unreadable).
std::ifstream OpenInputFile(const std::string& path);

// Size of the file `path` in bytes; the largest std::uintmax_t when it cannot
// be determined (e.g. a pipe), so that it bounds nothing.
// Readers compare the counts a file's header announces with it, so that a
// corrupt header fails with a message instead of an allocation of that size.
std::uintmax_t InputFileSize(const std::string& path);

}  // namespace diffpd
