#pragma once
// Patches with corners where r_u x r_v vanishes, for the tests of surface.hpp's cornerPieces
// and of everything that works on them (the Gauss map, optimal slicing).

#include <random>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::test {

// How a corner is made singular.
enum class CornerKind {
  coincidentAlongV,  ///< the corner's next control point along v equals it: r_v = 0 there
  coincidentAlongU,  ///< the same along u: r_u = 0 there
  parallel,          ///< the next point along v on the line through the next along u: r_u || r_v
};

struct CorneredPatch {
  BezierPatch patch;
  std::vector<int> corners;  ///< made singular (bit 0: u = 1, bit 1: v = 1)
  CornerKind kind = CornerKind::coincidentAlongV;
};

// A random graph-like patch of degrees 2..4 (p_jk = (k, j, z) jittered) with 1 to 4 of its
// corners made singular in one way. The result need not be regular elsewhere (the parallel
// kind can fold the patch): callers validate it.
inline CorneredPatch randomCorneredPatch(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> degree(2, 4), cornerCount(1, 4), kind(0, 2), corner(0, 3);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), height(-1.0, 1.0), ratio(0.2, 2.0);
  CorneredPatch out;
  BezierPatch& p = out.patch;
  p.degreeU = degree(rng);
  p.degreeV = degree(rng);
  for (int j = 0; j <= p.degreeU; ++j) {
    for (int k = 0; k <= p.degreeV; ++k) p.control.push_back({k + jitter(rng), j + jitter(rng), height(rng)});
  }
  out.kind = static_cast<CornerKind>(kind(rng));
  const int count = cornerCount(rng);
  while (static_cast<int>(out.corners.size()) < count) {
    const int c = corner(rng);
    bool seen = false;
    for (int other : out.corners) seen = seen || other == c;
    if (!seen) out.corners.push_back(c);
  }
  auto at = [&](int j, int k) -> Vec3& { return p.control[static_cast<std::size_t>(j * (p.degreeV + 1) + k)]; };
  for (int c : out.corners) {
    const int j0 = (c & 1) ? p.degreeU : 0, k0 = (c & 2) ? p.degreeV : 0;
    const int j1 = (c & 1) ? j0 - 1 : 1, k1 = (c & 2) ? k0 - 1 : 1;
    switch (out.kind) {
      case CornerKind::coincidentAlongV: at(j0, k1) = at(j0, k0); break;
      case CornerKind::coincidentAlongU: at(j1, k0) = at(j0, k0); break;
      case CornerKind::parallel: {
        const double lambda = (ratio(rng) < 1.1 ? -1.0 : 1.0) * ratio(rng);
        at(j0, k1) = at(j0, k0) + lambda * (at(j1, k0) - at(j0, k0));
        break;
      }
    }
  }
  return out;
}

}  // namespace scallop::test
