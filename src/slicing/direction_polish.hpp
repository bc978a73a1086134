#pragma once
// Private to the library: the polish of a slicing direction on the true surface (the
// derivation is at the top of direction_polish.cpp). From a seed N near the optimum (the
// medial axis's circle), a trust-region SQP on the minimax problem
//   minimise F(N) = max over the surface of |n(u, v) . N|,  |N| = 1
// whose model is built from the contacts (the local maxima of |n . N| over each patch).
// Quadratic near a vertex of three contacts or an edge of two; at most 200 steps, each a
// contact search of about 20 Newton climbs (~1 ms per seed on a bicubic patch). Polls
// checkCancelled() once per step.

#include <cstddef>
#include <memory>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::detail {

/// A unit vector orthogonal to n (|n| = 1).
Vec3 unitOrthogonal(const Vec3& n);

class ContactFinder;

/// The polish on one surface; its contact finder (the normals on each patch's parameter
/// grid) is built once and serves every seed.
class DirectionPolish {
 public:
  explicit DirectionPolish(const Surface& surface);
  ~DirectionPolish();
  DirectionPolish(const DirectionPolish&) = delete;
  DirectionPolish& operator=(const DirectionPolish&) = delete;

  /// The polished direction from `seed`, with F(N) = cos(alpha) in `value`; the first trust
  /// region's half-width is `initialRadius` (rad).
  Vec3 polish(const Vec3& seed, double initialRadius, double& value) const;

  /// Seeds independent of the Gauss map: the `count` best directions of a Fibonacci lattice
  /// of `directions` on the upper hemisphere, more than `separationRad` apart (see
  /// ContactFinder::latticeSeeds in direction_polish.cpp).
  std::vector<Vec3> latticeSeeds(int directions, std::size_t count, double separationRad) const;

 private:
  std::unique_ptr<ContactFinder> finder_;
};

}  // namespace scallop::detail
