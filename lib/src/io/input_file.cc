#include "diffpd/input_file.h"

#include <filesystem>
#include <limits>
#include <system_error>

#include "diffpd/error.h"

namespace diffpd {

std::ifstream OpenInputFile(const std::string& path) {
  std::error_code error;
  if (std::filesystem::is_directory(path, error))
    throw InvalidInputError("cannot open '" + path + "': it is a directory, not a file");
  std::ifstream in(path);
  if (!in) throw InvalidInputError("cannot open '" + path + "'");
  return in;
}

std::uintmax_t InputFileSize(const std::string& path) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  return error ? std::numeric_limits<std::uintmax_t>::max() : size;
}

}  // namespace diffpd
