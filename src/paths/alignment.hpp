#pragma once
// Private to the library: the local maxima of |n(u, v) . m| over a patch (n the unit
// normal, m a unit direction), where planes with normal m come nearest to tangency.
// Used by contour.cpp (minimumAngleBound) and raster.cpp (the best feed angle).

#include <algorithm>
#include <cmath>
#include <utility>

#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::detail {

struct AlignmentPeak {
  double value = 0.0;  ///< |n . m| at (u, v)
  double u = 0.0;
  double v = 0.0;
};

/// Climbs |n . m| from `start` by a shrinking pattern search in the parameter square (eight
/// directions, steps halving from `step` while above `finest`): a true local maximum to
/// about `finest` in (u, v), not a sample.
inline AlignmentPeak climbAlignment(const BezierPatch& patch, const Vec3& m, AlignmentPeak start,
                                    double step, double finest) {
  AlignmentPeak c = start;
  for (; step > finest; step *= 0.5) {
    for (bool moved = true; moved;) {
      moved = false;
      for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1},
                                   std::pair{0, -1}, std::pair{1, 1}, std::pair{-1, -1},
                                   std::pair{1, -1}, std::pair{-1, 1}}) {
        const double u = std::clamp(c.u + du * step, 0.0, 1.0);
        const double v = std::clamp(c.v + dv * step, 0.0, 1.0);
        const double g = std::abs(dot(unitNormal(patch, u, v), m));
        if (g > c.value) c = {g, u, v}, moved = true;
      }
    }
  }
  return c;
}

}  // namespace scallop::detail
