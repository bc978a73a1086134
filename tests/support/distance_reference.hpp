#pragma once
// A reference for the distance from a point to a surface of Bezier patches, written for the
// tests independently of gouge.hpp: every patch sampled on a dense grid, the best grid
// points refined by a derivative-free pattern search. Its refined distance is attained by
// a surface point, so it is never below the true distance; it misses the true minimum only
// when no start lies in the right basin (fine grids make that rare; tests that rely on it
// say how).

#include <algorithm>
#include <cmath>
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
// On a long, thin or sheared parameterization it crawls: use metricPatternSearch there.
inline double patternSearch(const BezierPatch& patch, Vec3 p, double u, double v, double h) {
  double best = distanceAt(patch, p, u, v);
  while (h > 1e-13) {
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

// The same compass search, but in the directions of the surface's own metric instead of the
// parameter axes, for patches whose parameterization is long, thin or sheared (a patch stretched
// a thousand times along one way, with its control rows jittered across, has level sets of
// |r(u, v) - p| that are ellipses of aspect ~1000 at an angle to the axes; the plain search
// crawls along them by steps far below its distance to the minimum, and stops at a piece's edge).
// At the start and after every halving, the metric G = J^T J of the patch at (u, v) is estimated
// by central differences of point() (so nothing is shared with the code under test but the
// evaluation), and the search tries the eight moves +-b1, +-b2, +-b1 +- b2 of a basis with
// (J b_i) orthonormal, scaled to a length h in space, plus the four parameter-axis moves scaled
// likewise (so that a minimum on the border of [0, 1]^2, where clamping bends the metric moves,
// is still reached along it). h starts at `step` (a length in space) and stops below `minStep`;
// `maxMoves` bounds the work. The result is attained by a surface point: an upper bound.
struct MetricSearch {
  double distance = 0.0;
  double u = 0.0;
  double v = 0.0;
  long moves = 0;
  bool budgetReached = false;
};

inline MetricSearch metricPatternSearch(const BezierPatch& patch, Vec3 p, double u, double v, double step,
                                        double minStep, long maxMoves) {
  MetricSearch result{distanceAt(patch, p, u, v), u, v, 0, false};
  double h = step;
  double bu[4] = {}, bv[4] = {};  // four of the twelve moves per unit length; the rest are their negatives
  double g11 = 0.0, g12 = 0.0, g22 = 0.0;  // the metric at the last estimate
  const auto estimateMetric = [&] {
    const double e = 1e-6;
    const double ua = std::max(0.0, u - e), ub = std::min(1.0, u + e);
    const double va = std::max(0.0, v - e), vb = std::min(1.0, v + e);
    const Vec3 ru = (point(patch, ub, v) - point(patch, ua, v)) / (ub - ua);
    const Vec3 rv = (point(patch, u, vb) - point(patch, u, va)) / (vb - va);
    g11 = dot(ru, ru);
    g12 = dot(ru, rv);
    g22 = dot(rv, rv);
    // G = Q diag(l1, l2) Q^T; the basis is Q diag(l1, l2)^(-1/2), each column of length 1 in
    // space. A degenerate metric (a collapsed edge) is floored so the moves stay finite.
    const double mean = 0.5 * (g11 + g22), half = 0.5 * (g11 - g22);
    const double radius = std::sqrt(half * half + g12 * g12);
    const double floor = 1e-12 * std::max(mean, 1e-300);
    const double l1 = std::max(mean + radius, floor), l2 = std::max(mean - radius, floor);
    const double angle = 0.5 * std::atan2(2.0 * g12, g11 - g22);
    const double c = std::cos(angle), s = std::sin(angle);
    bu[0] = c / std::sqrt(l1);
    bv[0] = s / std::sqrt(l1);
    bu[1] = -s / std::sqrt(l2);
    bv[1] = c / std::sqrt(l2);
    bu[2] = 1.0 / std::sqrt(std::max(g11, floor));
    bv[2] = 0.0;
    bu[3] = 0.0;
    bv[3] = 1.0 / std::sqrt(std::max(g22, floor));
  };
  estimateMetric();
  while (h > minStep) {
    if (result.moves >= maxMoves) {
      result.budgetReached = true;
      break;
    }
    ++result.moves;
    double bestU = u, bestV = v;
    const auto tryMove = [&](double du, double dv) {
      const double tu = std::clamp(u + h * du, 0.0, 1.0);
      const double tv = std::clamp(v + h * dv, 0.0, 1.0);
      // A move the border cut to under a quarter of its length is left out: beside the border
      // such short moves would keep succeeding where the full ones overshoot, and the step
      // would never halve (a crawl along the border).
      const double mu = tu - u, mv = tv - v;
      if (g11 * mu * mu + 2.0 * g12 * mu * mv + g22 * mv * mv < 0.0625 * h * h) return;
      const double d = distanceAt(patch, p, tu, tv);
      if (d < result.distance) {
        result.distance = d;
        bestU = tu;
        bestV = tv;
      }
    };
    for (double sign : {1.0, -1.0}) {
      for (int k = 0; k < 4; ++k) tryMove(sign * bu[k], sign * bv[k]);
      tryMove(sign * (bu[0] + bu[1]), sign * (bv[0] + bv[1]));
      tryMove(sign * (bu[0] - bu[1]), sign * (bv[0] - bv[1]));
    }
    if (bestU == u && bestV == v) {
      h *= 0.5;
      estimateMetric();
    } else {
      u = bestU;
      v = bestV;
      h = std::min(2.0 * h, step);  // a success lets the step grow back: no crawl along a valley
    }
  }
  result.u = u;
  result.v = v;
  return result;
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
