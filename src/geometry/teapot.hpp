#pragma once
// Private to the library: the Utah teapot's control points (teapot.cpp), from which
// surface.cpp builds the "teapot" examples.

#include <cstddef>

#include "scallop/geometry/bezier.hpp"

namespace scallop::detail {

/// Newell's teapot has 32 bicubic patches: rim 0-3, upper body 4-7, lower body 8-11,
/// handle 12-15, spout 16-19, lid knob 20-23, lid 24-27, bottom 28-31.
constexpr std::size_t kTeapotPatchCount = 32;

/// Patch `index` (< kTeapotPatchCount) of the teapot, in inches, z up.
BezierPatch teapotPatch(std::size_t index);

}  // namespace scallop::detail
