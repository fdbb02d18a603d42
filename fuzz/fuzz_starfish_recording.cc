// libFuzzer harness: ReadStarfishRecording on arbitrary bytes.
#include <cstddef>
#include <cstdint>

#include "calibration/starfish_recording.h"
#include "diffpd/error.h"
#include "fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = diffpd::fuzz::WriteInput(data, size, ".csv");
  try {
    diffpd::problems::ReadStarfishRecording(path);
  } catch (const diffpd::InvalidInputError&) {
  }
  return 0;
}
