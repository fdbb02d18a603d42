// The README's code blocks as the tests that check them see them: a block
// is the first ```cpp fence after a marker comment, up to its closing fence.
#pragma once

#include <fstream>
#include <iterator>
#include <string>

namespace diffpd::testing {

// The whole file at `path` ("" when it cannot be read).
inline std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// The code of the first ```cpp block after `marker` in `readme` (without
// its fences); "" when the marker or a fence is missing.
inline std::string CodeBlockAfter(const std::string& readme, const std::string& marker) {
  const size_t section = readme.find(marker);
  if (section == std::string::npos) return "";
  const std::string fence = "```cpp\n";
  const size_t begin = readme.find(fence, section);
  if (begin == std::string::npos) return "";
  const size_t end = readme.find("```", begin + fence.size());
  if (end == std::string::npos) return "";
  return readme.substr(begin + fence.size(), end - begin - fence.size());
}

}  // namespace diffpd::testing
