#pragma once
// A reference for the distance from a point to a surface of Bezier patches, written for the
// tests independently of gouge.hpp: every patch sampled on a dense grid, the best grid
// points refined by a derivative-free pattern search. Its refined distance is attained by
// a surface point, so it is never below the true distance; it misses the true minimum only
// when no start lies in the right basin (fine grids make that rare; tests that rely on it
// say how).

#include <algorithm>
#include <cstddef>
#include <limits>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::reference {

struct Reference {
  double sampled = std::numeric_limits<double>::infinity();  // least distance on the grid
  double refined = std::numeric_limits<double>::infinity();  // after the pattern search
};

inline double distanceAt(const BezierPatch& patch, Vec3 p, double u, double v) {
  return norm(point(patch, u, v) - p);
}

// A compass (pattern) search on [0, 1]^2 from (u, v): try the eight neighbours at step h,
// move to the best if it improves, else halve h. It needs no derivatives, so it shares
// nothing with the Newton polish of the code under test; with eight directions every
// descent direction is within 22.5 degrees of one, so it stops only at a local minimum.
// `maxMoves` bounds the steps, moves and halvings (the search stops there with its best point, still an upper
// bound): on a badly scaled piece it can crawl by steps far below its distance to the minimum.
inline double patternSearch(const BezierPatch& patch, Vec3 p, double u, double v, double h,
                            long maxMoves = std::numeric_limits<long>::max()) {
  double best = distanceAt(patch, p, u, v);
  for (long moves = 0; h > 1e-13 && moves < maxMoves; ++moves) {
    double bestU = u;
    double bestV = v;
    for (int du = -1; du <= 1; ++du) {
      for (int dv = -1; dv <= 1; ++dv) {
        if (du == 0 && dv == 0) continue;
        const double tu = std::clamp(u + du * h, 0.0, 1.0);
        const double tv = std::clamp(v + dv * h, 0.0, 1.0);
        const double d = distanceAt(patch, p, tu, tv);
        if (d < best) {
          best = d;
          bestU = tu;
          bestV = tv;
        }
      }
    }
    if (bestU == u && bestV == v) {
      h *= 0.5;
    } else {
      u = bestU;
      v = bestV;
    }
  }
  return best;
}

// Every patch sampled on a (grid + 1)^2 grid; the `starts` best grid points of each patch
// refined by the pattern search.
inline Reference referenceDistance(const Surface& surface, Vec3 p, int grid = 32, int starts = 4) {
  Reference reference;
  for (const BezierPatch& patch : surface.patches) {
    struct Sample {
      double d;
      double u;
      double v;
    };
    std::vector<Sample> samples;
    for (int i = 0; i <= grid; ++i) {
      for (int j = 0; j <= grid; ++j) {
        const double u = static_cast<double>(i) / grid;
        const double v = static_cast<double>(j) / grid;
        samples.push_back({distanceAt(patch, p, u, v), u, v});
      }
    }
    std::partial_sort(samples.begin(), samples.begin() + starts, samples.end(),
                      [](const Sample& a, const Sample& b) { return a.d < b.d; });
    reference.sampled = std::min(reference.sampled, samples[0].d);
    for (int s = 0; s < starts; ++s) {
      const Sample& start = samples[static_cast<std::size_t>(s)];
      reference.refined =
          std::min(reference.refined, patternSearch(patch, p, start.u, start.v, 1.0 / grid));
    }
  }
  return reference;
}

}  // namespace scallop::reference
