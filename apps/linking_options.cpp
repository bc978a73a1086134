#include "linking_options.hpp"

#include <string_view>

#include <fmt/format.h>

namespace scallop::cli {

void addLinkingOptions(CLI::App& command, bool& noLinking, bool& oneWay, std::string& rapidRate) {
  command.add_flag("--no-linking", noLinking,
                   "keep the strategy's pass order and its retracts to the safe height");
  command.add_flag("--one-way", oneWay,
                   "linking never runs a pass backwards (one cutting side: climb or conventional "
                   "throughout); default: zigzag where it shortens the links");
  command
      .add_option("--rapid-rate", rapidRate,
                  "rapid (G0) rate for the cycle time estimate, units per minute (default 200 "
                  "in/min or 5000 mm/min)")
      ->type_name("RATE");
}

std::string cycleSummary(const PathsReport& report, Units units) {
  if (!report.motion) return "no cycle time";
  const GcodeMotion& m = *report.motion;
  const std::string_view u = unitsName(units);
  std::string out = fmt::format(
      "cycle {:.2f} min (cutting {:.2f} min, {:.1f} {}; rapid {:.1f} {}; plunge {:.1f} {})",
      m.minutes, m.feedMinutes, m.feedLength, u, m.rapidLength, u, m.plungeLength, u);
  if (report.linking)
    out += fmt::format(", {} direct links, {} local retracts, {} safe retracts",
                       report.linking->directLinks, report.linking->localRetracts,
                       report.linking->unprovenLinks);
  return out;
}

}  // namespace scallop::cli
