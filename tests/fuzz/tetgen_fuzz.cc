// libFuzzer target for the TetGen reader. The input is the .node text, a line starting with
// "#.ele" (a TetGen comment), then the .ele text; without that line the .ele text is empty.
// Only InputError may escape the parser; a parsed mesh must be valid (tests/fuzz/fuzz_checks.h).
#include "plugin/tetgen_reader.h"
#include "tests/fuzz/fuzz_checks.h"

// One fuzz input.
extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text = taut::fuzz::AsText(data, size);
  const std::size_t split = text.find("#.ele");
  const std::string_view node = text.substr(0, split);
  const std::string_view ele = split == std::string_view::npos ? "" : text.substr(split + 5);
  try {
    taut::fuzz::CheckParsedTetMesh(
        taut::internal::ParseTetGenMesh(node, "fuzz.node", ele, "fuzz.ele"));
  } catch (const taut::InputError&) {
  }
  return 0;
}
