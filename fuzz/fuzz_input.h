// The fuzz input as the files a reader opens: each harness process writes the
// bytes to its own temporary file (readers take paths) and calls the reader.
// A reader may refuse the input with InvalidInputError; anything else it
// throws, and any sanitizer report, is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace diffpd::fuzz {

// Writes `size` bytes to <temp>/diffpd-fuzz-<pid><suffix> and returns the path.
inline std::string WriteInput(const uint8_t* data, size_t size, const std::string& suffix) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("diffpd-fuzz-" + std::to_string(getpid()) + suffix)).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace diffpd::fuzz
