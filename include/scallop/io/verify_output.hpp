#pragma once
// The cut simulation's report (cut_simulation.hpp) as JSON and as a heat map in SVG.
//
// JSON (verifyToJson): one object, keys in this order:
//   {"surface", "program", "units", "tool_radius", "scallop_height", "gouge_tolerance",
//    "stock_top", "grid": {"origin": [x, y], "spacing", "columns", "rows", "points",
//    "surface_points", "height_error_bound"},
//    "moves": {"total", "rapids", "arcs", "rapids_cutting", "first_rapid_cut_line" | null,
//              "unknown_start", "max_arc_radius_mismatch"},
//    "gouge": {"max", "at": [x, y, z] | null, "points", "area", "over_tolerance": bool},
//    "scallop": {"max", "at": [x, y, z] | null, "p99", "mean", "uncut_points", "uncut_area"},
//    "swept_point_visits"}
// No wall times (the CLI prints them on stderr): the same program gives the same bytes.
// Lengths in the surface's units, areas in units^2; numbers shortest round-trip (full
// double precision), never NaN or infinite (a missing location is null).
//
// SVG (verifySvg): the footprint seen from above (x right, y up), each grid point's verdict
// as a colour: scallop height ((stock - design) |n_z|) on a 10-step scale from 0 to 2H (the last
// step "2H or more"), gouges (design - stock > tolerance) on a 5-step red scale, logarithmic
// from the tolerance to the deepest, points without surface light grey; the deepest gouge marked by a
// ring; two colour bars with units, a title and a line of figures. Size: the grid is
// drawn in blocks of b x b points (b = ceil(max(columns, rows) / 200), a block taking its
// worst point: its deepest gouge if it has one, else its highest scallop), each row's runs
// of blocks of one colour merged into one rectangle, and the rectangles of one colour drawn
// as one path in block units ("M a b h n v 1 h -n z", about 15 bytes a run): at most
// 200 x 200 runs (600 kB); 100-300 kB on the paper's plans. Deterministic.

#include <string>

#include "scallop/paths/cut_simulation.hpp"

namespace scallop {

/// Where the inputs came from, for the outputs' titles.
struct VerifySources {
  std::string surface;
  std::string program;
  std::size_t unknownStartMoves = 0;
  double maxArcRadiusMismatch = 0.0;
};

std::string verifyToJson(const SimulationReport& report, const VerifySources& sources);
std::string verifySvg(const SimulationReport& report, const VerifySources& sources);

}  // namespace scallop
