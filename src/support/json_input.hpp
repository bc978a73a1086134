#pragma once
// Private to the library: reading a JSON document (surfaces, chains) with its nesting
// bounded. Why: nlohmann's parser keeps its own stack, but every recursive walk of the value
// afterwards (dump, used to quote a bad value in a message; comparisons; copies) takes one
// stack frame per level, and a document nested 80,000 deep overflowed the stack. scallop's
// documents are at most 5 levels deep (a surface: object, patches, patch, rows, point).

#include <string>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "scallop/error.hpp"

namespace scallop::detail {

/// Deepest nesting of arrays and objects accepted.
inline constexpr int kMaxJsonDepth = 64;

/// nlohmann's messages start with "[json.exception.parse_error.101] "; the rest (line,
/// column, what was expected) is what a user needs.
inline std::string withoutExceptionId(const std::string& message) {
  if (!message.empty() && message.front() == '[') {
    const std::size_t close = message.find("] ");
    if (close != std::string::npos) return message.substr(close + 2);
  }
  return message;
}

/// The document in `text`; scallop::Error "<source>: malformed JSON: ..." for a syntax error
/// (with line and column), a number beyond the range of a double, or nesting deeper than
/// kMaxJsonDepth (refused while parsing, before any of it is built deeper).
inline nlohmann::json parseJsonDocument(std::string_view text, const std::string& source) {
  struct TooDeep {};
  try {
    return nlohmann::json::parse(text.begin(), text.end(),
                                 [](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
                                   if (depth > kMaxJsonDepth) throw TooDeep{};
                                   return true;
                                 });
  } catch (const TooDeep&) {
    throw Error(fmt::format("{}: malformed JSON: arrays or objects nested more than {} levels deep", source,
                            kMaxJsonDepth));
  } catch (const nlohmann::json::exception& error) {
    throw Error(fmt::format("{}: malformed JSON: {}", source, withoutExceptionId(error.what())));
  }
}

}  // namespace scallop::detail
