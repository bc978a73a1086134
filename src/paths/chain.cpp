#include "scallop/paths/chain.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {

void validateChain(std::span<const Point2> chain) {
  if (chain.size() < 2) {
    throw Error(fmt::format("a chain needs at least 2 points, got {}", chain.size()));
  }
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const Point2& p = chain[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.z)) {
      throw Error(fmt::format("point {}: coordinates must be finite numbers, got ({}, {})", i,
                              p.x, p.z));
    }
    if (i > 0 && p.x < chain[i - 1].x) {
      throw Error(fmt::format(
          "point {}: x decreases from {} (point {}) to {}; the chain must be monotone "
          "(x non-decreasing)",
          i, chain[i - 1].x, i - 1, p.x));
    }
  }
}

double coordinateScale(std::span<const Point2> chain) {
  double scale = 0.0;
  for (const Point2& p : chain) {
    scale = std::max({scale, std::abs(p.x), std::abs(p.z)});
  }
  return scale;
}

}  // namespace scallop
