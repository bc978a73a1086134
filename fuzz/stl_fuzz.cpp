// libFuzzer target: the STL reader (mesh.hpp: binary or ASCII by content), with and without
// dropping triangles of zero area.
#include "fuzz_target.hpp"
#include "scallop/geometry/mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return scallop::fuzz::run(data, size, [](std::string_view bytes) {
    scallop::StlOptions options;
    options.dropZeroArea = bytes.size() % 2 == 1;
    (void)scallop::looksLikeStl(bytes, bytes.size());
    (void)scallop::parseStl(bytes, "fuzz.stl", options);
  });
}
