// libFuzzer target for the OFF reader: only InputError may escape the parser; a parsed surface
// must have finite vertices and in-range indices, and a closed one is voxelized
// (tests/fuzz/fuzz_checks.h).
#include "plugin/off_reader.h"
#include "tests/fuzz/fuzz_checks.h"

// One fuzz input.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    taut::fuzz::CheckParsedSurface(
        taut::internal::ParseOffSurface(taut::fuzz::AsText(data, size), "fuzz.off"));
  } catch (const taut::InputError&) {
  }
  return 0;
}
