#include "support/examples.hpp"
#include "support/input_file.hpp"
#include "support/json_input.hpp"
#include "support/text_input.hpp"
#include "scallop/io/chain_io.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "scallop/error.hpp"

namespace scallop {
namespace {

using detail::clipped;
using detail::displayName;
using detail::isBlank;
using detail::trim;

// ---------------------------------------------------------------------------------------
// Shared helpers
// ---------------------------------------------------------------------------------------


// validateChain is the authority on the chain invariant; the parsers check the same
// conditions first so that they can name the line or point, and this catches anything a
// future change to the invariant adds.
void validateParsedChain(const Chain& chain, const std::string& source) {
  try {
    validateChain(chain);
  } catch (const Error& error) {
    throw Error(fmt::format("{}: {}", source, error.what()));
  }
}

// ---------------------------------------------------------------------------------------
// Text format
// ---------------------------------------------------------------------------------------


// The line without its comment and surrounding blanks.
std::string_view stripComment(std::string_view line) {
  const std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  return trim(line);
}

[[noreturn]] void throwAtLine(const std::string& source, std::size_t line, std::string_view what,
                              std::string_view token) {
  throw Error(fmt::format("{}:{}: {} '{}'", source, line, what, clipped(token)));
}

// Splits a trimmed, non-empty line into fields separated by blanks and/or one comma.
// Two commas in a row, or a comma at either end, leave an empty field: an error.
std::vector<std::string_view> splitFields(std::string_view line, const std::string& source,
                                          std::size_t lineNumber) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (true) {
    const std::size_t start = i;
    while (i < line.size() && !isBlank(line[i]) && line[i] != ',') ++i;
    if (i == start) throwAtLine(source, lineNumber, "empty field (stray comma) in", line);
    fields.push_back(line.substr(start, i - start));
    if (i == line.size()) return fields;
    while (i < line.size() && isBlank(line[i])) ++i;
    if (line[i] == ',') {
      ++i;
      while (i < line.size() && isBlank(line[i])) ++i;
      if (i == line.size()) throwAtLine(source, lineNumber, "empty field (stray comma) in", line);
    }
  }
}

enum class NumberStatus {
  ok,
  notNumber,   // does not start with a number: a header word, or garbage
  trailing,    // a number followed by other characters ("1.5mm")
  outOfRange,  // beyond the range of a double
  notFinite,   // "nan", "inf", "infinity"
};

struct ParsedNumber {
  double value = 0.0;
  NumberStatus status = NumberStatus::notNumber;
};

// std::from_chars is locale-independent and exact (correctly rounded). It rejects a leading
// '+', which people do write, so one is skipped when a digit or '.' follows.
ParsedNumber parseNumber(std::string_view token) {
  if (token.size() > 1 && token.front() == '+' && token[1] != '+' && token[1] != '-') {
    token.remove_prefix(1);
  }
  ParsedNumber parsed;
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, parsed.value);
  if (error == std::errc::invalid_argument) {
    parsed.status = NumberStatus::notNumber;
  } else if (stop != end) {
    parsed.status = NumberStatus::trailing;
  } else if (error == std::errc::result_out_of_range) {
    parsed.status = NumberStatus::outOfRange;
  } else if (!std::isfinite(parsed.value)) {
    parsed.status = NumberStatus::notFinite;
  } else {
    parsed.status = NumberStatus::ok;
  }
  return parsed;
}

double numberOrThrow(std::string_view token, const std::string& source, std::size_t line) {
  const ParsedNumber parsed = parseNumber(token);
  switch (parsed.status) {
    case NumberStatus::ok:
      return parsed.value;
    case NumberStatus::notNumber:
      throwAtLine(source, line, "expected a number, got", token);
    case NumberStatus::trailing:
      throwAtLine(source, line, "unexpected characters after the number in", token);
    case NumberStatus::outOfRange:
      throwAtLine(source, line, "number out of the range of a double", token);
    case NumberStatus::notFinite:
      throwAtLine(source, line, "coordinates must be finite numbers, got", token);
  }
  throwAtLine(source, line, "cannot read number", token);
}

bool isHeader(const std::vector<std::string_view>& fields) {
  return std::all_of(fields.begin(), fields.end(), [](std::string_view field) {
    return parseNumber(field).status == NumberStatus::notNumber;
  });
}

struct TextVertex {
  Point2 point;
  std::size_t line = 0;
};

// Checks a new vertex against the previous one: x may repeat (a vertical edge) but never
// decrease. Done here rather than left to validateChain so that the message names lines.
void checkMonotone(const std::vector<TextVertex>& vertices, const TextVertex& next,
                   std::string_view xToken, const std::string& source) {
  if (vertices.empty() || !(next.point.x < vertices.back().point.x)) return;
  const TextVertex& previous = vertices.back();
  throwAtLine(source, next.line,
              fmt::format("x decreases (the chain must have x non-decreasing; line {} has x = {}), "
                          "got x =",
                          previous.line, previous.point.x),
              xToken);
}

Chain parseTextChain(std::string_view content, const std::string& source) {
  std::vector<TextVertex> vertices;
  bool seenDataLine = false;
  std::size_t lineNumber = 0;
  std::size_t position = 0;
  while (position < content.size()) {
    const std::size_t newline = std::min(content.find('\n', position), content.size());
    const std::string_view line = stripComment(content.substr(position, newline - position));
    position = newline + 1;
    ++lineNumber;
    if (line.empty()) continue;

    const std::vector<std::string_view> fields = splitFields(line, source, lineNumber);
    const bool firstDataLine = !seenDataLine;
    seenDataLine = true;
    if (firstDataLine && isHeader(fields)) continue;

    const double x = numberOrThrow(fields[0], source, lineNumber);
    if (fields.size() < 2) throwAtLine(source, lineNumber, "missing z value after x =", fields[0]);
    const double z = numberOrThrow(fields[1], source, lineNumber);
    if (fields.size() > 2) throwAtLine(source, lineNumber, "unexpected third field", fields[2]);

    const TextVertex vertex{Point2{x, z}, lineNumber};
    checkMonotone(vertices, vertex, fields[0], source);
    vertices.push_back(vertex);
  }

  if (vertices.empty()) throw Error(fmt::format("{}: no points", source));
  if (vertices.size() == 1) {
    throw Error(fmt::format("{}:{}: only one point; a chain needs at least 2", source,
                            vertices.front().line));
  }
  Chain chain;
  chain.reserve(vertices.size());
  for (const TextVertex& vertex : vertices) chain.push_back(vertex.point);
  return chain;
}

// ---------------------------------------------------------------------------------------
// JSON format
// ---------------------------------------------------------------------------------------


[[noreturn]] void throwAtPoint(const std::string& source, std::size_t index, std::string_view what,
                               const nlohmann::json& value) {
  throw Error(fmt::format("{}: points[{}]: {} {}", source, index, what, clipped(value.dump())));
}

Point2 jsonPoint(const nlohmann::json& value, std::size_t index, const std::string& source) {
  if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number()) {
    throwAtPoint(source, index, "expected [x, z] numbers, got", value);
  }
  const Point2 point{value[0].get<double>(), value[1].get<double>()};
  // JSON has no NaN or infinity (and nlohmann rejects literals that overflow); kept as a
  // guard so that the chain invariant never rests on the JSON library's behaviour.
  if (!std::isfinite(point.x) || !std::isfinite(point.z)) {
    throwAtPoint(source, index,
                 "coordinates must be finite numbers (within the range of a double), got", value);
  }
  return point;
}

Chain parseJsonChain(std::string_view content, const std::string& source) {
  nlohmann::json document = detail::parseJsonDocument(content, source);
  if (!document.is_object() || !document.contains("points") || !document["points"].is_array()) {
    throw Error(fmt::format("{}: expected a JSON object {{\"points\": [[x, z], ...]}}", source));
  }

  const nlohmann::json& points = document["points"];
  Chain chain;
  chain.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Point2 point = jsonPoint(points[i], i, source);
    if (!chain.empty() && point.x < chain.back().x) {
      throwAtPoint(source, i,
                   fmt::format("x decreases (the chain must have x non-decreasing; points[{}] has "
                               "x = {}), got",
                               i - 1, chain.back().x),
                   points[i]);
    }
    chain.push_back(point);
  }
  if (chain.empty()) throw Error(fmt::format("{}: no points", source));
  if (chain.size() == 1) {
    throw Error(fmt::format("{}: points[0]: only one point; a chain needs at least 2", source));
  }
  return chain;
}

bool looksLikeJson(std::string_view content) {
  const std::size_t first = content.find_first_not_of(" \t\r\n\f\v");
  return first != std::string_view::npos && content[first] == '{';
}

// ---------------------------------------------------------------------------------------
// Reading files
// ---------------------------------------------------------------------------------------


// ---------------------------------------------------------------------------------------
// Built-in examples
// ---------------------------------------------------------------------------------------

// In the spirit of the paper's Figure 2 (for r = 1): a bumpy stretch with two deep pits
// too narrow for the circle, a peak, a long slope with a third pit, and a gentle tail.
Chain figure2Chain() {
  return {{0.0, 2.0}, {0.8, 2.3}, {1.2, 2.1}, {1.5, 2.6},  {1.9, 2.2},  {2.3, 2.5}, {2.5, 0.6},
          {2.7, 0.5}, {2.9, 2.6}, {3.4, 2.9}, {3.8, 2.7},  {4.1, 3.1},  {4.3, 1.2}, {4.6, 3.2},
          {5.4, 4.6}, {5.8, 5.2}, {6.1, 4.9}, {6.6, 4.0},  {7.4, 3.0},  {8.2, 2.2}, {8.5, 2.3},
          {8.7, 1.0}, {8.9, 1.9}, {9.8, 1.4}, {10.4, 1.7}, {11.2, 1.5}, {12.0, 1.6}};
}

// Terraces joined by vertical edges going up and down, with a slot 0.5 wide (for r = 0.5,
// a slot of the tool's radius: the tool bridges it).
Chain stepsChain() {
  return {{0.0, 0.0}, {1.0, 0.0},  {1.0, 1.0},  {2.0, 1.0}, {2.0, 2.5}, {3.5, 2.5}, {3.5, 1.5},
          {4.5, 1.5}, {4.5, 0.25}, {5.0, 0.25}, {5.0, 1.5}, {6.5, 1.5}, {6.5, 0.5}, {8.0, 0.5}};
}

// Ten teeth: a slow rise over 0.85 then a steep fall over 0.15 (for r = 0.5, every valley
// is a deficiency).
Chain sawtoothChain() {
  constexpr int kTeeth = 10;
  Chain chain;
  for (int k = 0; k < kTeeth; ++k) {
    chain.push_back({static_cast<double>(k), 0.0});
    chain.push_back({k + 0.85, 1.0});
  }
  chain.push_back({static_cast<double>(kTeeth), 0.0});
  return chain;
}

// z = sin(x) over two periods, 201 samples. Its troughs have radius of curvature 1: a tool
// of r < 1 follows the whole wave, r = 2 leaves a lid over each trough.
Chain sineChain() {
  constexpr int kIntervals = 200;
  constexpr double kLength = 4.0 * std::numbers::pi;
  Chain chain;
  chain.reserve(kIntervals + 1);
  for (int i = 0; i <= kIntervals; ++i) {
    const double x = kLength * i / kIntervals;
    chain.push_back({x, std::sin(x)});
  }
  return chain;
}

constexpr detail::Example<Chain> kExamples[] = {
    {"figure2", figure2Chain},
    {"steps", stepsChain},
    {"sawtooth", sawtoothChain},
    {"sine", sineChain},
};

}  // namespace

Chain parseChain(std::string_view content, const std::string& sourceName) {
  const std::string source = displayName(sourceName);
  // A UTF-8 byte order mark, as some editors write, is not content.
  constexpr std::string_view kByteOrderMark = "\xEF\xBB\xBF";
  if (content.substr(0, kByteOrderMark.size()) == kByteOrderMark) {
    content.remove_prefix(kByteOrderMark.size());
  }
  Chain chain =
      looksLikeJson(content) ? parseJsonChain(content, source) : parseTextChain(content, source);
  validateParsedChain(chain, source);
  return chain;
}

Chain readChain(const std::string& path) { return parseChain(detail::readInputFile(path), path); }

std::vector<std::string> exampleChainNames() {
  return detail::exampleNames<Chain>(kExamples);
}

Chain exampleChain(const std::string& name) {
  return detail::makeExample<Chain>(kExamples, name, "chain");
}

}  // namespace scallop
