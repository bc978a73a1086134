#pragma once
// Monotone chains: the section of a surface by a vertical plane, as a polyline in that
// plane. Coordinates are (x, z): x along the section, z the height (tool axis). Units are
// whatever the caller's are (mm or inches); every length scallop returns is in the same unit.

#include <cstddef>
#include <span>
#include <vector>

namespace scallop {

/// A point in a vertical section plane: x horizontal, z up.
struct Point2 {
  double x = 0.0;
  double z = 0.0;
  friend bool operator==(const Point2&, const Point2&) = default;
};

/// A monotone chain v_0 .. v_{n-1} (0-based; the paper's v_1 .. v_n). Invariant, checked by
/// validateChain: n >= 2, every coordinate finite, x non-decreasing (equal x = a vertical
/// edge; repeated points allowed). Material lies below the chain and below the two downward
/// vertical rays from its end points.
using Chain = std::vector<Point2>;

/// Throws scallop::Error naming the first offending vertex (0-based index and value) when
/// the chain has fewer than 2 points, a NaN or infinite coordinate, or x decreasing.
void validateChain(std::span<const Point2> chain);

/// The largest absolute coordinate of the chain: the scale the tolerances refer to.
double coordinateScale(std::span<const Point2> chain);

}  // namespace scallop
