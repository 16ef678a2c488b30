// libFuzzer target for the OBJ reader (tinyobjloader from a string): only InputError may escape
// the parser; a parsed surface must have finite vertices and in-range indices, and a closed one
// is voxelized (tests/fuzz/fuzz_checks.h).
#include "plugin/obj_surface_reader.h"
#include "tests/fuzz/fuzz_checks.h"

// One fuzz input.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    taut::fuzz::CheckParsedSurface(
        taut::internal::ParseObjSurface(taut::fuzz::AsText(data, size), "fuzz.obj"));
  } catch (const taut::InputError&) {
  }
  return 0;
}
