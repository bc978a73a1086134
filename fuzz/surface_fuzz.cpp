// libFuzzer target: the surface readers (surface.hpp's JSON, surface_io.hpp's .bpt), each
// with the full check, and the patch selection of the CLI's --patches.
#include "fuzz_target.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/io/surface_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return scallop::fuzz::run(data, size, [](std::string_view text) {
    // The first byte picks the reader, so that one corpus feeds all three.
    if (text.empty()) return;
    const char pick = text.front();
    text.remove_prefix(1);
    if (pick % 3 == 0) {
      (void)scallop::parseSurface(text, "fuzz.json");
    } else if (pick % 3 == 1) {
      (void)scallop::parseBptSurface(text, "fuzz.bpt");
    } else {
      (void)scallop::parsePatchSelection(text, 1000);
    }
  });
}
