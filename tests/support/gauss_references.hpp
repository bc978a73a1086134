#pragma once
// What the Gauss map and optimal slicing tests share: dense surface normals for their
// brute-force references, the brute-force optimal slicing angle, and a surface that once
// broke the Gauss map.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <utility>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop::reference {

// Unit normals on an (n+1) x (n+1) parameter grid of every patch.
inline std::vector<Vec3> sampleNormals(const Surface& s, int n) {
  std::vector<Vec3> out;
  for (const BezierPatch& p : s.patches) {
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= n; ++j) out.push_back(unitNormal(p, double(i) / n, double(j) / n));
    }
  }
  return out;
}

// The least angle between direction m and +-(the sampled normals): alpha of m over the
// samples, and the angle from m to the sampled symmetrized Gauss image.
inline double sampledAlpha(const std::vector<Vec3>& normals, const Vec3& m) {
  double worst = 0.0;
  for (const Vec3& n : normals) worst = std::max(worst, std::abs(dot(n, m)));
  return std::acos(std::min(1.0, worst));
}

// ---------------------------------------------------------------------------------------
// Brute-force optimal slicing (the reference for optimal_slicing.hpp)
// ---------------------------------------------------------------------------------------
//
// alpha* = max over unit N of min over the surface of the angle between N and +-n, i.e.
// acos(min_N f(N)) with f(N) = max_n |N . n|, by sampling: f over the unit normals on a grid
// of each patch, minimised over N by screening a Fibonacci grid of the upper half sphere (N
// and -N are the same slicing direction) on a coarse set of normals, then refining the best
// few by a shrinking-pattern search on that set, and the best of those on the dense set.
// Independent of the library: the normals come from the Bernstein basis written out here
// (not bezier.hpp), and nothing of gauss_map or optimal_slicing is used.
//
// Singular points (collapsed rows or columns such as the teapot's apexes, where
// r_u x r_v = 0) are skipped: a sample is kept only where |r_u x r_v| > 1e-12 S_u S_v (the
// bounds of |r_u| and |r_v| from the control net); the samples around them give the limits
// of the normal.
//
// Accuracy: the sampled f is at most the true one (fewer normals), so alpha comes out at
// least the true alpha* up to the search's own error; with 128 x 128 cells per patch the gap
// is below ~1e-3 degrees on smooth patches (paper-1: 78.0476 vs the certified 78.0475). The
// search is a local one from the best directions of the screen: a global optimum that the
// screen ranks lower than `finalists` others would be missed (none was on the surfaces
// tested). Deterministic: no randomness, no threads.

// Samples (samples + 1) x (samples + 1) unit normals per patch, skipping singular points.
inline std::vector<Vec3> sampleRegularNormals(const Surface& s, int samples) {
  // b_i^n(t), all i, for one t: the binomial expansion written out.
  auto basis = [](int n, double t) {
    std::vector<double> b(static_cast<std::size_t>(n) + 1);
    for (int i = 0; i <= n; ++i) {
      double binomial = 1.0;
      for (int k = 1; k <= i; ++k) binomial = binomial * (n - i + k) / k;
      b[static_cast<std::size_t>(i)] = binomial * std::pow(t, i) * std::pow(1.0 - t, n - i);
    }
    return b;
  };
  std::vector<Vec3> out;
  for (const BezierPatch& p : s.patches) {
    const int m = p.degreeU;
    const int n = p.degreeV;
    double su = 0.0;
    double sv = 0.0;
    for (int j = 0; j <= m; ++j) {
      for (int k = 0; k <= n; ++k) {
        if (j < m) su = std::max(su, m * norm(p.at(j + 1, k) - p.at(j, k)));
        if (k < n) sv = std::max(sv, n * norm(p.at(j, k + 1) - p.at(j, k)));
      }
    }
    const double tiny = 1e-12 * su * sv;
    // The unit normal from the basis values in u (bu, du: degrees m and m - 1) and in v, kept
    // where r_u x r_v is not singular.
    auto addNormal = [&](const std::vector<double>& bu, const std::vector<double>& du,
                         const std::vector<double>& bv, const std::vector<double>& dv) {
      Vec3 ru{0.0, 0.0, 0.0};
      Vec3 rv{0.0, 0.0, 0.0};
      for (int j = 0; j <= m; ++j) {
        for (int k = 0; k <= n; ++k) {
          if (j < m) ru = ru + (m * du[j] * bv[k]) * (p.at(j + 1, k) - p.at(j, k));
          if (k < n) rv = rv + (n * bu[j] * dv[k]) * (p.at(j, k + 1) - p.at(j, k));
        }
      }
      const Vec3 normal = cross(ru, rv);
      const double length = norm(normal);
      if (length > tiny) out.push_back(normal / length);
    };
    for (int a = 0; a <= samples; ++a) {
      const double u = double(a) / samples;
      const std::vector<double> bu = basis(m, u);
      const std::vector<double> du = basis(m - 1, u);
      for (int c = 0; c <= samples; ++c) {
        const double v = double(c) / samples;
        addNormal(bu, du, basis(n, v), basis(n - 1, v));
      }
    }
    // Rays into each corner at 1e-6 of the parameter range: where r_u x r_v vanishes at a
    // corner, the normals' closure there is the arc of their limits along the rays, which a
    // grid never comes near (elsewhere these samples repeat the corner's normal).
    for (int corner = 0; corner < 4; ++corner) {
      const double u0 = (corner & 1) ? 1.0 : 0.0, v0 = (corner & 2) ? 1.0 : 0.0;
      for (int a = 0; a <= samples; ++a) {
        const double theta = 0.5 * std::numbers::pi * a / samples;
        const double u = u0 + (1.0 - 2.0 * u0) * 1e-6 * std::cos(theta);
        const double v = v0 + (1.0 - 2.0 * v0) * 1e-6 * std::sin(theta);
        addNormal(basis(m, u), basis(m - 1, u), basis(n, v), basis(n - 1, v));
      }
    }
  }
  return out;
}

struct BruteForceOptions {
  int samples = 128;       ///< dense normals: (samples + 1)^2 per patch (129 x 129)
  int screenSamples = 16;  ///< coarse normals for the screen and the first refinement
  int directions = 6000;   ///< Fibonacci points on the upper half sphere (~2.7 deg apart)
  int finalists = 8;       ///< directions refined on the coarse normals (mutually > 6 deg apart)
  int denseFinalists = 3;  ///< of which refined again on the dense normals
};

struct BruteForceSlicing {
  double alphaRad = 0.0;  ///< acos(f(direction)) on the dense normals
  Vec3 direction;         ///< the best N found (unit; z >= 0)
};

namespace detail {

// f(N) = max |N . n|.
inline double largestCosine(const std::vector<Vec3>& normals, const Vec3& direction) {
  double worst = 0.0;
  for (const Vec3& n : normals) worst = std::max(worst, std::abs(dot(n, direction)));
  return worst;
}

// Minimises f near `start` by a pattern search: a 9 x 9 grid of directions
// normalize(N + h (a e1 + b e2)), a, b in -4..4, around the current N in its tangent plane;
// move to the grid's best point, and halve h when that point is in the inner 5 x 5 or after
// 8 moves at one h (on a ridge of f the search zigzags across the valley, creeping); stop
// below hMin. Each step evaluates f only on the normals that can be largest within the
// grid's radius R = 4 sqrt(2) h: |N' . n| <= |N . n| + R and f(N') >= f(N) - R, so the
// others (|N . n| < f(N) - 2R) cannot.
inline std::pair<Vec3, double> refineDirection(const std::vector<Vec3>& normals, Vec3 direction,
                                               double h, double hMin) {
  double best = largestCosine(normals, direction);
  std::vector<Vec3> active;
  int moves = 0;
  while (h > hMin) {
    const double radius = 4.0 * std::numbers::sqrt2 * h;
    active.clear();
    for (const Vec3& n : normals) {
      if (std::abs(dot(n, direction)) >= best - 2.0 * radius) active.push_back(n);
    }
    // An orthonormal tangent frame at the current direction.
    const Vec3 helper = std::abs(direction.z) < 0.9 ? Vec3{0.0, 0.0, 1.0} : Vec3{1.0, 0.0, 0.0};
    const Vec3 e1 = normalized(cross(direction, helper));
    const Vec3 e2 = cross(direction, e1);
    Vec3 next = direction;
    double nextValue = best;
    int nextA = 0;
    int nextB = 0;
    for (int a = -4; a <= 4; ++a) {
      for (int b = -4; b <= 4; ++b) {
        if (a == 0 && b == 0) continue;
        const Vec3 candidate = normalized(direction + (a * h) * e1 + (b * h) * e2);
        const double value = largestCosine(active, candidate);
        if (value < nextValue) {
          next = candidate;
          nextValue = value;
          nextA = a;
          nextB = b;
        }
      }
    }
    direction = next;
    best = nextValue;
    if ((std::abs(nextA) <= 2 && std::abs(nextB) <= 2) || ++moves == 8) {
      h *= 0.5;
      moves = 0;
    }
  }
  return {direction, best};
}

// Polishes a near-optimal N to the exact optimum of the sampled problem. The optimum is the
// centre of the largest cap (with its antipode) free of the sampled normals +-n, so (barring
// a continuum of optima) it touches three of them, or two on opposite sides: N is the
// circumcentre of three of +-n (normalize((b - a) x (c - a))) or the midpoint of two
// (normalize(a + b)), the defining ones being among those nearest to +-N. Tries every triple
// and pair of the 24 normals nearest to +-N (with both signs) within 0.01 rad of N, keeps the
// best by f, and repeats from it while f decreases (3 rounds at most).
inline std::pair<Vec3, double> polishDirection(const std::vector<Vec3>& normals, Vec3 direction,
                                               double best) {
  constexpr double kReach = 0.01;
  constexpr std::size_t kNearest = 24;
  for (int round = 0; round < 3; ++round) {
    std::vector<std::pair<double, Vec3>> near;  // (|N . n|, n), the largest first
    std::vector<Vec3> active;                   // those that can be largest within kReach
    for (const Vec3& n : normals) {
      const double c = std::abs(dot(n, direction));
      if (c >= best - 2.0 * kReach) {
        active.push_back(n);
        near.emplace_back(c, n);
      }
    }
    const std::size_t count = std::min(kNearest, near.size());
    std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(count), near.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first; });
    Vec3 next = direction;
    double nextValue = best;
    auto consider = [&](Vec3 candidate) {
      const double length = norm(candidate);
      if (!(length > 1e-12)) return;
      candidate = candidate / length;
      if (dot(candidate, direction) < 0.0) candidate = -candidate;
      if (norm(candidate - direction) > kReach) return;
      const double value = largestCosine(active, candidate);
      if (value < nextValue) {
        next = candidate;
        nextValue = value;
      }
    };
    for (std::size_t i = 0; i < count; ++i) {
      const Vec3 a = near[i].second;
      for (std::size_t j = i + 1; j < count; ++j) {
        for (const double sj : {1.0, -1.0}) {
          const Vec3 b = sj * near[j].second;
          consider(a + b);
          for (std::size_t k = j + 1; k < count; ++k) {
            for (const double sk : {1.0, -1.0}) consider(cross(b - a, sk * near[k].second - a));
          }
        }
      }
    }
    if (!(nextValue < best)) break;
    direction = next;
    best = nextValue;
  }
  return {direction, best};
}

}  // namespace detail

// The brute-force optimal slicing angle alpha* and direction N* of a surface (see above).
// Cost (Release build): ~0.01-0.02 s for one bicubic patch, 0.3 s for the whole teapot (32
// patches, 530,000 dense normals); a flat patch (every normal alike, so every sample stays
// active in the polish) takes ~0.07 s.
inline BruteForceSlicing bruteForceOptimalAlpha(const Surface& s, const BruteForceOptions& o = {}) {
  const std::vector<Vec3> coarse = sampleRegularNormals(s, o.screenSamples);
  const std::vector<Vec3> dense = sampleRegularNormals(s, o.samples);
  // The screen: Fibonacci points, uniform in z on (0, 1) (equal areas), golden-angle spiral.
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  std::vector<std::pair<double, Vec3>> screened;
  for (int i = 0; i < o.directions; ++i) {
    const double z = (i + 0.5) / o.directions;
    const double r = std::sqrt(1.0 - z * z);
    const Vec3 d{r * std::cos(golden * i), r * std::sin(golden * i), z};
    screened.emplace_back(detail::largestCosine(coarse, d), d);
  }
  std::stable_sort(screened.begin(), screened.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  // The best directions at least 6 degrees apart (as lines: N and -N are the same).
  const double separation = std::cos(6.0 * std::numbers::pi / 180.0);
  const double spacing = std::sqrt(2.0 * std::numbers::pi / o.directions);
  std::vector<std::pair<double, Vec3>> refined;
  std::vector<Vec3> starts;
  for (const auto& [value, d] : screened) {
    if (static_cast<int>(starts.size()) == o.finalists) break;
    const bool near = std::any_of(starts.begin(), starts.end(), [&](const Vec3& other) {
      return std::abs(dot(other, d)) > separation;
    });
    if (near) continue;
    starts.push_back(d);
    const auto [direction, coarseValue] = detail::refineDirection(coarse, d, spacing, 1e-4);
    refined.emplace_back(coarseValue, direction);
  }
  std::stable_sort(refined.begin(), refined.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  BruteForceSlicing result;
  double bestValue = 2.0;
  for (int i = 0; i < std::min<int>(o.denseFinalists, static_cast<int>(refined.size())); ++i) {
    const auto [near, nearValue] =
        detail::refineDirection(dense, refined[static_cast<std::size_t>(i)].second, 4e-3, 1e-7);
    const auto [direction, value] = detail::polishDirection(dense, near, nearValue);
    if (value < bestValue) {
      bestValue = value;
      result.direction = direction.z < 0.0 ? -direction : direction;
    }
  }
  result.alphaRad = std::acos(std::min(1.0, bestValue));
  return result;
}

// Two bicubic graph patches over [0, 3] x [0, 3] and [3, 6] x [0, 3] with heights z[j][k] at
// (x, y) = (k, j), sharing the column k = 3 (C0).
inline Surface twoPatchSurface(const double (&z)[4][7]) {
  Surface s;
  for (int part = 0; part < 2; ++part) {
    BezierPatch p;
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) p.control.push_back({double(3 * part + k), double(j), z[j][3 * part + k]});
    }
    s.patches.push_back(p);
  }
  return s;
}

// Two random bicubic patches, C0 along x = 3, on which the Gauss map's union once lost the
// normals near the corner (u, v) = (0, 1) of the second patch (2,640 of 40,803 normals sampled
// at 101 x 101 lay more than two tolerances inside the complement, 34 degrees deep at worst).
inline Surface twoPatchRegressionSurface() {
  const double z[4][7] = {{0.6753, 1.1909, 1.2780, 0.7642, 0.6671, 0.9258, 1.0888},
                          {0.3085, 1.3275, 1.3722, 0.5354, 0.0021, 1.1797, 0.2465},
                          {0.5283, 1.0242, 0.4930, 0.2316, 1.0166, 0.2580, 0.6747},
                          {0.8372, 0.5874, 1.4148, 0.6583, 1.4150, 1.4974, 1.2883}};
  return twoPatchSurface(z);
}

// alpha(N) on the continuous surface, for a reference: the nearest of +-(the normals) to N,
// from (grid + 1)^2 samples per patch, the best sample of each patch refined by a shrinking
// pattern search in (u, v) (clamped to the patch). An upper estimate of the true alpha(N),
// converged to a local minimum of the angle: samples can only miss nearer normals.
inline double nearestNormalAngle(const Surface& s, const Vec3& direction, int grid = 200) {
  const Vec3 m = normalized(direction);
  double best = 10.0;
  for (const BezierPatch& patch : s.patches) {
    auto angleAt = [&](double u, double v) {
      try {
        return std::acos(std::min(1.0, std::abs(dot(unitNormal(patch, u, v), m))));
      } catch (const Error&) {
        return 10.0;  // a singular point: no normal (the limits are sampled beside it)
      }
    };
    double bu = 0.0, bv = 0.0, local = 10.0;
    for (int a = 0; a <= grid; ++a) {
      for (int b = 0; b <= grid; ++b) {
        const double value = angleAt(double(a) / grid, double(b) / grid);
        if (value < local) local = value, bu = double(a) / grid, bv = double(b) / grid;
      }
    }
    for (double step = 1.0 / grid; step > 1e-13;) {
      bool improved = false;
      for (int k = 0; k < 8; ++k) {
        const double phi = std::numbers::pi * k / 4.0;
        const double u = std::clamp(bu + step * std::cos(phi), 0.0, 1.0);
        const double v = std::clamp(bv + step * std::sin(phi), 0.0, 1.0);
        const double value = angleAt(u, v);
        if (value < local) local = value, bu = u, bv = v, improved = true;
      }
      if (!improved) step *= 0.5;
    }
    best = std::min(best, local);
    // Rays into each corner at 1e-6 (see sampleRegularNormals): the arc of limits where
    // r_u x r_v vanishes at a corner, sampled, the best ray refined by golden sections.
    for (int corner = 0; corner < 4; ++corner) {
      const double u0 = (corner & 1) ? 1.0 : 0.0, v0 = (corner & 2) ? 1.0 : 0.0;
      auto atRay = [&](double theta) {
        return angleAt(u0 + (1.0 - 2.0 * u0) * 1e-6 * std::cos(theta),
                       v0 + (1.0 - 2.0 * v0) * 1e-6 * std::sin(theta));
      };
      const int rays = 4 * grid;
      int bestRay = 0;
      double rayValue = 10.0;
      for (int a = 0; a <= rays; ++a) {
        const double value = atRay(0.5 * std::numbers::pi * a / rays);
        if (value < rayValue) rayValue = value, bestRay = a;
      }
      double lo = 0.5 * std::numbers::pi * std::max(0, bestRay - 1) / rays;
      double hi = 0.5 * std::numbers::pi * std::min(rays, bestRay + 1) / rays;
      const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
      for (int step = 0; step < 60; ++step) {
        const double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
        if (atRay(a) < atRay(b)) hi = b; else lo = a;
      }
      best = std::min({best, rayValue, atRay(0.5 * (lo + hi))});
    }
  }
  return best;
}

}  // namespace scallop::reference
