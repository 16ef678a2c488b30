// libFuzzer target for the Gmsh reader: only InputError may escape the parser, and a parsed mesh
// must be valid (tests/fuzz/fuzz_checks.h).
#include "plugin/gmsh_reader.h"
#include "tests/fuzz/fuzz_checks.h"

// One fuzz input.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    taut::fuzz::CheckParsedTetMesh(
        taut::internal::ParseGmshMesh(taut::fuzz::AsText(data, size), "fuzz.msh"));
  } catch (const taut::InputError&) {
  }
  return 0;
}
