// `scallop hull`: reads a chain (a file, standard input or a built-in example), computes its
// scallop hull and tool-centre path for a ball of radius r, and writes JSON and/or SVG.
// Every output is computed into memory first and the files are then written all or
// nothing, so a failed run leaves no output behind.

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "arguments.hpp"
#include "commands.hpp"
#include "scallop/io/chain_io.hpp"
#include "scallop/error.hpp"
#include "scallop/io/file_output.hpp"
#include "scallop/io/hull_json.hpp"
#include "scallop/io/hull_svg.hpp"
#include "scallop/paths/path_sampling.hpp"
#include "scallop/paths/scallop_hull.hpp"

namespace scallop::cli {
namespace {

constexpr const char* kStandardStream = "-";

struct HullOptions {
  std::string input;      // FILE, or "-" for standard input
  std::string example;    // --example NAME
  std::string radius;     // --radius R, parsed by parseRadius (accepts "inf")
  std::string jsonPath;   // --json OUT
  std::string svgPath;    // --svg OUT
  std::string tolerance;  // --tolerance T, parsed by parsePositive
};

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// r > 0, or "inf"/"infinity" for the r = infinity limit (the upper convex hull).
double parseRadius(const std::string& text) {
  const std::string word = lowercase(text);
  if (word == "inf" || word == "infinity" || word == "+inf" || word == "+infinity") {
    return kInfiniteRadius;
  }
  return parsePositive(text, "radius", "a positive number, or 'inf' for an infinite radius");
}

// Checks the combination of options, which CLI11 cannot express: exactly one input, and
// outputs that do not collide.
void checkOptions(const HullOptions& options) {
  if (options.input.empty() == options.example.empty()) {
    throw CLI::ValidationError("hull", "give the chain either as FILE or as --example NAME");
  }
  if (options.jsonPath == kStandardStream && options.svgPath == kStandardStream) {
    throw CLI::ValidationError("hull", "--json and --svg cannot both write to standard output");
  }
  if (!options.tolerance.empty() && options.jsonPath.empty() && !options.svgPath.empty()) {
    throw CLI::ValidationError("hull",
                               "--tolerance adds a polyline to the JSON output: give --json too");
  }
}

// Where the JSON goes: --json, or standard output when no output is named at all.
std::string jsonDestination(const HullOptions& options) {
  if (!options.jsonPath.empty()) return options.jsonPath;
  return options.svgPath.empty() ? std::string(kStandardStream) : std::string();
}

// How the summary names the input.
std::string sourceName(const HullOptions& options) {
  if (!options.example.empty()) return "example " + options.example;
  return options.input == kStandardStream ? std::string("<stdin>") : options.input;
}

std::size_t countLinks(const ScallopHull& result) {
  return static_cast<std::size_t>(
      std::count_if(result.hull.begin(), result.hull.end(),
                    [](const HullElement& e) { return e.kind == HullElementKind::link; }));
}

void printSummary(const std::string& source, std::size_t vertices, const ScallopHull& result,
                  double seconds, const std::vector<OutputFile>& outputs) {
  const std::size_t links = countLinks(result);
  std::string written;
  for (const OutputFile& output : outputs) {
    written += (written.empty() ? "" : ", ") + output.path;
  }
  fmt::print(stderr,
             "scallop: {}: n = {}, r = {}, {} links, {} lids, tool path length {:.6g}, "
             "{:.6f} s -> {}\n",
             source, vertices, result.radius, links, result.hull.size() - links,
             pathLength(result.toolpath), seconds, written);
}

void runHull(const HullOptions& options) {
  checkOptions(options);
  const double radius = parseRadius(options.radius);
  const bool sampled = !options.tolerance.empty();
  const double tolerance =
      sampled ? parsePositive(options.tolerance, "tolerance", "a positive number") : 0.0;

  const bool fromExample = !options.example.empty();
  const std::string source = sourceName(options);
  const Chain chain = fromExample ? exampleChain(options.example) : readChain(options.input);

  const auto started = std::chrono::steady_clock::now();
  const ScallopHull result = [&] {
    try {
      return scallopHull(chain, radius);
    } catch (const Error& error) {
      throw Error(fmt::format("{}: {}", source, error.what()));  // the chain's scale, say
    }
  }();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  std::vector<OutputFile> outputs;
  const std::string jsonPath = jsonDestination(options);
  if (!jsonPath.empty()) {
    outputs.push_back({jsonPath, sampled ? hullToJson(result, chain.size(), samplePath(result.toolpath, tolerance))
                                         : hullToJson(result, chain.size())});
  }
  if (!options.svgPath.empty()) outputs.push_back({options.svgPath, hullToSvg(chain, result)});
  writeFilesAtomically(outputs);

  // The summary goes to stderr, but stays quiet when the JSON is piped on standard output.
  if (jsonPath != kStandardStream) printSummary(source, chain.size(), result, seconds, outputs);
}

}  // namespace

void addHullCommand(CLI::App& app) {
  // Owned by the callback, which outlives this function (CLI11's pattern for subcommands
  // defined in their own file).
  auto options = std::make_shared<HullOptions>();
  CLI::App* hull = app.add_subcommand(
      "hull", "Scallop hull of a chain and the ball-end tool-centre path, as JSON and/or SVG");
  hull->footer(
      "Computes the scallop hull of a monotone chain (links where a ball of radius R touches "
      "the chain, lids over the deficiencies it cannot reach) and its offset, the path of the "
      "ball's centre (lines and clockwise arcs). Writes JSON (to standard output if neither "
      "--json nor --svg is given) and/or an SVG picture; outputs are written all or nothing.\n"
      "Input: text, one vertex \"x z\" per line (blanks and/or one comma between the two; '#' "
      "comments; an optional header line), or JSON {\"points\": [[x, z], ...]}; x must never "
      "decrease (equal x = a vertical edge); material lies below the chain.\n"
      "Example: scallop hull --example figure2 --radius 1 --json out.json --svg out.svg");

  CLI::Option* file =
      hull->add_option("FILE", options->input, "chain file (text or JSON); - reads standard input")
          ->type_name("");
  CLI::Option* example =
      hull->add_option("--example", options->example, "use a built-in example chain instead")
          ->check(CLI::IsMember(exampleChainNames()))
          ->type_name("NAME");
  file->excludes(example);
  hull->add_option("-r,--radius", options->radius,
                   "ball radius R > 0, in the chain's unit; 'inf' gives the upper convex hull")
      ->required()
      ->type_name("R");
  hull->add_option("--json", options->jsonPath,
                   "write the hull, tool path and statistics as JSON to OUT (- = standard output)")
      ->type_name("OUT");
  hull->add_option("--svg", options->svgPath,
                   "write a picture of the chain, hull and tool path to OUT (- = standard output)")
      ->type_name("OUT");
  hull->add_option("--tolerance", options->tolerance,
                   "also give the tool path as a polyline (JSON key \"polyline\") that stays "
                   "outside the true path and at most T beyond it")
      ->type_name("T");
  hull->callback([options] { runHull(*options); });
}

}  // namespace scallop::cli
