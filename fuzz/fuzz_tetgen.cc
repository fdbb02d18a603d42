// libFuzzer harness: ReadTetGen on arbitrary bytes. The input up to its first
// NUL byte is the .node file, the rest the .ele file (no NUL: an empty .ele).
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "diffpd/error.h"
#include "diffpd/tetgen_io.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const void* nul = std::memchr(data, 0, size);
  const size_t node_size = nul ? static_cast<size_t>(static_cast<const uint8_t*>(nul) - data) : size;
  const size_t ele_offset = nul ? node_size + 1 : size;
  const std::string node = diffpd::fuzz::WriteInput(data, node_size, ".node");
  const std::string ele = diffpd::fuzz::WriteInput(data + ele_offset, size - ele_offset, ".ele");
  try {
    diffpd::ReadTetGen(node, ele);
  } catch (const diffpd::InvalidInputError&) {
  }
  return 0;
}
