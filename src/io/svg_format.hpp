#pragma once
// Private to the library: number formatting shared by scallop's SVG writers (hull_svg.cpp,
// orient_output.cpp). Every number they write is fixed-point, so no picture ever holds an
// exponent, "nan" or "inf".

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop::svg {

/// A page coordinate in pixels: a fixed three decimals, finer than any screen or printer,
/// never an exponent; "-0.000" is written "0.000". Throws scallop::Error for a non-finite
/// value (a bug upstream: a picture must never hold "nan" or "inf").
inline std::string px(double value) {
  if (!std::isfinite(value)) throw Error("cannot draw a picture: a coordinate is not finite");
  const std::string text = fmt::format("{:.3f}", value);
  return text == "-0.000" ? std::string("0.000") : text;
}

/// A length for a label: six significant digits, fixed notation (no exponent however large
/// or small), trailing zeros dropped.
inline std::string lengthLabel(double value) {
  if (value == 0.0) return "0";
  const int magnitude = static_cast<int>(std::floor(std::log10(std::abs(value))));
  const int decimals = std::clamp(5 - magnitude, 0, 340);
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find('.') != std::string::npos) {
    text.erase(text.find_last_not_of('0') + 1);
    if (text.back() == '.') text.pop_back();
  }
  return text;
}

/// The largest length of the form {1, 2, 5} x 10^k not longer than `limit` (> 0): the
/// length of a scale bar.
inline double roundLength(double limit) {
  const double power = std::pow(10.0, std::floor(std::log10(limit)));
  for (const double step : {5.0, 2.0, 1.0}) {
    if (step * power <= limit) return step * power;
  }
  return power;
}

}  // namespace scallop::svg
