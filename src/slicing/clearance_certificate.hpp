#pragma once
// Private to the library: the clearance certificate of a slicing direction. certifyPieces
// proves, by subdivision of Bernstein polynomials (no sampling), that no surface normal
// comes within `lowerBoundRad` of +-n on a surface whose corners are resolved already
// (cornerPieces), so that optimalSlicing's bisection can call it many times on the same
// pieces; certifyClearance (optimal_slicing.hpp) resolves the corners first. At most
// 4^maxDepth cells per piece, counted in `cells`; polls checkCancelled() every 64 cells.

#include <cstddef>

#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::detail {

bool certifyPieces(const Surface& pieces, const Vec3& n, double lowerBoundRad, std::size_t& cells,
                   int maxDepth);

}  // namespace scallop::detail
