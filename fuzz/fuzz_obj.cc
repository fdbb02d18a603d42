// libFuzzer harness: ReadObj on arbitrary bytes.
#include <cstddef>
#include <cstdint>

#include "diffpd/surface_mesh.h"
#include "diffpd/error.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = diffpd::fuzz::WriteInput(data, size, ".obj");
  try {
    diffpd::ReadObj(path);
  } catch (const diffpd::InvalidInputError&) {
  }
  return 0;
}
