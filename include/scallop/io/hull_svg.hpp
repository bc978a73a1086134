#pragma once
// A picture of a scallop hull in the spirit of the paper's Figures 2 and 4: the chain with
// its material shaded, the scallop hull (links, lids drawn as arcs), the tool-centre path,
// the tool's circle at each lid centre, a scale bar and a legend. Self-contained SVG.

#include <span>
#include <string>

#include "scallop/paths/chain.hpp"
#include "scallop/paths/scallop_hull.hpp"

namespace scallop {

std::string hullToSvg(std::span<const Point2> chain, const ScallopHull& result);

}  // namespace scallop
