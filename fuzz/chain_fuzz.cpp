// libFuzzer target: the chain reader (chain_io.hpp: text, CSV or JSON by content), then the
// scallop hull of what it accepts at a finite and an infinite radius (scallop_hull.hpp).
#include "fuzz_target.hpp"
#include "scallop/io/chain_io.hpp"
#include "scallop/paths/scallop_hull.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return scallop::fuzz::run(data, size, [](std::string_view text) {
    const scallop::Chain chain = scallop::parseChain(text, "fuzz");
    (void)scallop::scallopHull(chain, 1.0);
    (void)scallop::scallopHull(chain, scallop::kInfiniteRadius);
  });
}
