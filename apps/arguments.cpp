#include "arguments.hpp"

#include <charconv>
#include <cmath>
#include <sstream>
#include <vector>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/geometry/vector.hpp"

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

Vec3 parseNormal(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  for (std::string part; std::getline(stream, part, ',');) parts.push_back(part);
  if (parts.size() != 3 || text.back() == ',')
    throw Error(fmt::format("invalid normal '{}': expected X,Y,Z (three numbers) or auto", text));
  const Vec3 n{parseFinite(parts[0], "normal x", "a number"),
               parseFinite(parts[1], "normal y", "a number"),
               parseFinite(parts[2], "normal z", "a number")};
  if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0)
    throw Error(fmt::format("invalid normal '{}': the zero vector has no direction", text));
  if (!std::isfinite(norm(n)))
    throw Error(fmt::format("invalid normal '{}': too large", text));
  return n;
}

}  // namespace scallop::cli
