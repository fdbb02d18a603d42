// libFuzzer harness: ReadReferenceCurve on arbitrary bytes.
#include <cstddef>
#include <cstdint>

#include "control/reference_curve.h"
#include "diffpd/error.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = diffpd::fuzz::WriteInput(data, size, ".csv");
  try {
    diffpd::problems::ReadReferenceCurve(path, "fuzz");
  } catch (const diffpd::InvalidInputError&) {
  }
  return 0;
}
