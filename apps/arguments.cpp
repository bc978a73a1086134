#include "arguments.hpp"

#include <charconv>
#include <cmath>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop::cli {

double parseFinite(const std::string& text, const char* what, const char* expected) {
  std::string_view digits = text;
  if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') {
    digits.remove_prefix(1);
  }
  double value = 0.0;
  const char* end = digits.data() + digits.size();
  const auto [stop, error] = std::from_chars(digits.data(), end, value);
  if (digits.empty() || stop != end || error == std::errc::invalid_argument) {
    throw Error(fmt::format("invalid {} '{}': expected {}", what, text, expected));
  }
  if (error == std::errc::result_out_of_range) {
    throw Error(fmt::format("invalid {} '{}': out of the range of a double", what, text));
  }
  if (std::isnan(value)) {
    throw Error(fmt::format("invalid {} '{}': not a number; expected {}", what, text, expected));
  }
  if (std::isinf(value)) {
    throw Error(fmt::format("invalid {} '{}': expected {}", what, text, expected));
  }
  return value;
}

double parsePositive(const std::string& text, const char* what, const char* expected) {
  const double value = parseFinite(text, what, expected);
  if (!(value > 0.0)) {
    throw Error(fmt::format("invalid {} '{}': must be positive", what, text));
  }
  return value;
}

}  // namespace scallop::cli
