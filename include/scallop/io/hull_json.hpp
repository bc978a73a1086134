#pragma once
// JSON form of a scallop hull and its tool path (the `scallop hull --json` output).
//
// {"radius": r (null when infinite), "hull": [{"kind": "link"|"lid", "start": [x, z],
//  "end": [x, z], "center": [x, z] (finite lids only), "edge": i (links only)}, ...],
//  "toolpath": [{"kind": "line", "start", "end"} | {"kind": "arc", "start", "end", "center",
//  "radius", "clockwise"}, ...], "toolpath_length": length of the tool path,
//  "polyline": [[x, z], ...] (only from the overload taking one), "stats": {"vertices",
//  "links", "lids", "stack_pushes", "stack_pops", "comparisons"}}
// Numbers are written with the shortest representation that round-trips to the same double.
// No wall time: the same hull gives the same bytes (the CLI prints its timing on stderr).
// Keys appear in this order; each hull element, path element and polyline point is on a
// line of its own.

#include <span>
#include <string>

#include "scallop/paths/chain.hpp"
#include "scallop/paths/scallop_hull.hpp"

namespace scallop {

/// Serialises `result` for a chain of `vertexCount` vertices.
std::string hullToJson(const ScallopHull& result, std::size_t vertexCount);

/// As above, plus a "polyline" key holding `polyline` (the tool path sampled by samplePath).
std::string hullToJson(const ScallopHull& result, std::size_t vertexCount, std::span<const Point2> polyline);

}  // namespace scallop
