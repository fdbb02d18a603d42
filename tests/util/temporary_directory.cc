#include "util/temporary_directory.h"

#include <stdlib.h>  // mkdtemp

#include <cerrno>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace diffpd::testing {

TemporaryDirectory::TemporaryDirectory(const std::string& prefix) {
  if (prefix.empty() || prefix.find('/') != std::string::npos) {
    throw std::invalid_argument("TemporaryDirectory: prefix '" + prefix + "' must be non-empty without '/'");
  }
  std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "-XXXXXX")).string();
  if (mkdtemp(pattern.data()) == nullptr) {
    throw std::runtime_error("TemporaryDirectory: cannot create a directory like '" + pattern +
                             "': " + std::generic_category().message(errno));
  }
  path_ = std::filesystem::absolute(pattern);
}

TemporaryDirectory::~TemporaryDirectory() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::string TemporaryDirectory::File(const std::string& name) const { return (path_ / name).string(); }

std::string TemporaryDirectory::WriteFile(const std::string& name, const std::string& text) const {
  const std::string path = File(name);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
  out.close();
  if (!out) throw std::runtime_error("TemporaryDirectory: cannot write '" + path + "'");
  return path;
}

}  // namespace diffpd::testing
