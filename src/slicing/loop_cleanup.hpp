#pragma once
// Private to the library: the Gauss map's loops made fit for the medial axis (simple,
// disjoint). See withoutSpikes in loop_cleanup.cpp for why and by how much the boundary moves.

#include <vector>

#include "scallop/geometry/vector.hpp"

namespace scallop::detail {

/// The loops without the zero-width zigzags and sliver holes thinner than `widthRad` on the
/// sphere (measured in the stereographic plane). O(n).
std::vector<std::vector<Vec2>> withoutSpikes(const std::vector<std::vector<Vec2>>& loops, double widthRad);

}  // namespace scallop::detail
