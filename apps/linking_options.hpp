#pragma once
// Command-line pieces of linking and the cycle time that `paths` and `plan` share:
// --no-linking, --one-way, --rapid-rate, and the summary line's cycle-time part.

#include <string>

#include <CLI/CLI.hpp>

#include "scallop/io/paths_output.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop::cli {

/// --no-linking (keep the strategy's order and its safe-height retracts), --one-way (never
/// run a pass backwards: one cutting side throughout) and --rapid-rate RATE (units per
/// minute, for the cycle time; default 200 in/min or 5000 mm/min).
void addLinkingOptions(CLI::App& command, bool& noLinking, bool& oneWay, std::string& rapidRate);

/// "cycle 1.23 min (cutting 1.00 min, 210.0 in; rapid 12.3 in; plunge 1.7 in); 80 direct
/// links, 2 local retracts": the report's motion and linking, for the summary line.
std::string cycleSummary(const PathsReport& report, Units units);

}  // namespace scallop::cli
