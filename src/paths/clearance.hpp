#pragma once
// Private to the library: proofs that a ball-end cutter's centre keeps clear of a surface
// along a straight move, shared by the raster strategy's pass ends and links (raster.cpp)
// and the linking of passes (linking.cpp).
//   HeightBound:   a proven upper bound of the surface's height over the horizontal
//                  R-neighbourhood of a segment (branch and bound on sub-patches).
//   segmentClears: sphere tracing on gouge.hpp's proven distance lower bound along a segment.

#include "scallop/paths/gouge.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::detail {

/// Sphere-tracing steps segmentClears takes by default before it gives up.
inline constexpr int kSegmentMaxSteps = 4000;

// The highest z of the surface over the horizontal R-neighbourhood of a segment, bounded
// from above by branch and bound: a sub-patch lies in the convex hull of its control
// points, so under its box's top, and outside the neighbourhood if its box's footprint is.
// Corner points of the sub-patches in the neighbourhood are surface points: their highest z
// is a lower bound, and the search stops once the best box is within `tolerance` of it.
class HeightBound {
 public:
  HeightBound(const Surface& surface, double tolerance, double slack)
      : surface_(surface), tolerance_(tolerance), slack_(slack) {}

  // >= z of every surface point at horizontal distance < radius from [a, b]; -inf if
  // there is none.
  double above(Vec2 a, Vec2 b, double radius) const;

 private:
  const Surface& surface_;
  double tolerance_;
  double slack_;
};

// Proves that the ball, its centre moving along [a, b], stays at least `need` from the
// surface: sphere tracing on the distance's proven lower bound. dist(., surface) is
// 1-Lipschitz, so a centre p with dist(p) >= need + m clears every centre within m of p;
// each step advances by that margin. Gives up (false) when the margin falls below
// `minStep` (the path comes too close, or creeps along the limit) or after `maxSteps`
// (raster's pass ends: kSegmentMaxSteps).
bool segmentClears(const SurfaceDistance& distance, Vec3 a, Vec3 b, double need,
                   double reach, double minStep, int maxSteps = kSegmentMaxSteps);

}  // namespace scallop::detail
