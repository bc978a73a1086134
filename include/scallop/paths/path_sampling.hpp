#pragma once
// Turning a tool path with arcs into a polyline, for consumers that cannot take arcs.
//
// Contract: input a tool path as produced by scallopHull (contiguous elements, clockwise
// upper arcs); a chordal tolerance t > 0 in the path's length unit. Output: a polyline that
// starts and ends at the path's end points, keeps every line element exactly, and replaces
// every arc by a circumscribed polygon: each polygon edge lies on a tangent line of the arc,
// so the polyline never passes inside the true path (never closer to the material), and is
// at most t farther from the arc centre than r. O(sum of arc angle / sqrt(t / r)) points.

#include <span>
#include <vector>

#include "scallop/paths/chain.hpp"
#include "scallop/paths/scallop_hull.hpp"

namespace scallop {

/// Circumscribed polyline of `toolpath` within chordal tolerance `tolerance` (> 0).
/// Throws scallop::Error if the tolerance is not a positive finite number.
std::vector<Point2> samplePath(std::span<const PathElement> toolpath, double tolerance);

}  // namespace scallop
