// libFuzzer target: the G-code reader (gcode_reader.hpp), then the swept moves the cut
// simulation takes from what it accepts (cut_simulation.hpp).
#include "fuzz_target.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/io/gcode_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return scallop::fuzz::run(data, size, [](std::string_view text) {
    const scallop::GcodeProgram program = scallop::parseGcodeProgram(text, "fuzz.ngc");
    (void)scallop::sweptMoves(program, 0.25);
  });
}
