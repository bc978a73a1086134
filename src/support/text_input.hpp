#pragma once
// Private to the library: what the text readers (chains, .json and .bpt surfaces) share for
// naming their source and quoting the offending text in error messages.

#include <cstddef>
#include <string>
#include <string_view>

namespace scallop::detail {

/// The longest stretch of offending text quoted in a message.
inline constexpr std::size_t kMaxQuotedLength = 60;

/// The text, cut after kMaxQuotedLength characters ("...": a runaway line, a binary file).
inline std::string clipped(std::string_view text) {
  if (text.size() <= kMaxQuotedLength) return std::string(text);
  return std::string(text.substr(0, kMaxQuotedLength)) + "...";
}

/// How a source is named in messages: "-" is standard input.
inline std::string displayName(const std::string& sourceName) {
  return sourceName == "-" ? std::string("<stdin>") : sourceName;
}

/// Blanks within a line: space, tab, carriage return, form feed, vertical tab.
inline bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// The text without leading and trailing blanks.
inline std::string_view trim(std::string_view text) {
  while (!text.empty() && isBlank(text.front())) text.remove_prefix(1);
  while (!text.empty() && isBlank(text.back())) text.remove_suffix(1);
  return text;
}

}  // namespace scallop::detail
