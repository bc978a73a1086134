#include "scallop/contour.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "scallop/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/optimal_slicing.hpp"

namespace scallop {
namespace {

void requirePositive(const char* what, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw Error(fmt::format("{} must be a positive number, got {}", what, value));
}

// |n . m| at (u, v), n the unit normal: the cosine of the angle between m and +-n.
double alignment(const BezierPatch& patch, const Vec3& m, double u, double v) {
  return std::abs(dot(unitNormal(patch, u, v), m));
}

}  // namespace

Vec3 upwardNormal(const Surface& surface, std::size_t patch, double u, double v) {
  const BezierPatch& p = surface.patches.at(patch);
  const Vec3 n = unitNormal(p, u, v);
  // One orientation per patch, the one whose centre normal points up, so that the offset
  // does not flip side where the surface is steep.
  const double centreZ = unitNormal(p, 0.5, 0.5).z;
  return centreZ >= 0.0 ? n : -n;
}

double spacingForScallopHeight(double toolRadius, double scallopHeight, double alphaRad) {
  requirePositive("the tool radius", toolRadius);
  requirePositive("the scallop height", scallopHeight);
  if (scallopHeight >= toolRadius)
    throw Error(fmt::format("the scallop height {} must be smaller than the tool radius {}",
                            scallopHeight, toolRadius));
  if (!(alphaRad > 0.0) || alphaRad > std::numbers::pi / 2.0 + 1e-12)
    throw Error(fmt::format(
        "the slicing planes come within {:.4f} degrees of tangency to the surface: no plane "
        "spacing bounds the scallop height there; give a spacing, or use the optimal normal",
        alphaRad * 180.0 / std::numbers::pi));
  // h = R - sqrt(R^2 - l^2/4)  <=>  l = 2 sqrt(2 R h - h^2); Delta = l sin(alpha).
  const double stepOver =
      2.0 * std::sqrt(2.0 * toolRadius * scallopHeight - scallopHeight * scallopHeight);
  return stepOver * std::sin(alphaRad);
}

double minimumAngleBound(const Surface& surface, const Vec3& direction) {
  const double length = norm(direction);
  if (!std::isfinite(length) || length == 0.0)
    throw Error(fmt::format("the direction ({}, {}, {}) must be finite and non-zero", direction.x,
                            direction.y, direction.z));
  const Vec3 m = direction / length;
  // Estimate: the largest |n . m| on a grid, each patch's best samples climbed by a
  // shrinking pattern search (the true local maxima, not the samples).
  constexpr int kGrid = 48;
  double largest = 0.0;
  for (const BezierPatch& patch : surface.patches) {
    struct Sample {
      double value, u, v;
    };
    std::vector<Sample> samples;
    for (int i = 0; i <= kGrid; ++i)
      for (int j = 0; j <= kGrid; ++j) {
        const double u = double(i) / kGrid, v = double(j) / kGrid;
        samples.push_back({alignment(patch, m, u, v), u, v});
      }
    constexpr int kClimbed = 16;
    std::partial_sort(samples.begin(), samples.begin() + kClimbed, samples.end(),
                      [](const Sample& a, const Sample& b) { return a.value > b.value; });
    for (int s = 0; s < kClimbed; ++s) {
      Sample c = samples[static_cast<std::size_t>(s)];
      for (double step = 1.0 / kGrid; step > 1e-12; step *= 0.5) {
        for (bool moved = true; moved;) {
          moved = false;
          for (const auto& [du, dv] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1},
                                       std::pair{0, -1}, std::pair{1, 1}, std::pair{-1, -1},
                                       std::pair{1, -1}, std::pair{-1, 1}}) {
            const double u = std::clamp(c.u + du * step, 0.0, 1.0);
            const double v = std::clamp(c.v + dv * step, 0.0, 1.0);
            const double g = alignment(patch, m, u, v);
            if (g > c.value) c = {g, u, v}, moved = true;
          }
        }
      }
      largest = std::max(largest, c.value);
    }
  }
  const double estimate = std::acos(std::min(1.0, largest));
  // Prove a bound a little below the estimate, backing off until the certificate holds:
  // first by absolute margins, then (for small angles, where the certificate's polynomial
  // A = cos^2(a) |N|^2 - (N . m)^2 has little room) by halving.
  std::vector<double> candidates;
  for (double margin = 1e-7; margin < 0.5 * estimate && margin < 0.01; margin *= 4.0)
    candidates.push_back(estimate - margin);
  for (double bound = 0.5 * estimate; bound > 1e-6; bound *= 0.5) candidates.push_back(bound);
  for (double bound : candidates) {
    std::size_t cells = 0;
    if (certifyClearance(surface, m, bound, cells)) return bound;
  }
  return 0.0;
}

ContourPaths contourPaths(const Surface& surface, const ContourOptions& options) {
  validateSurface(surface);
  const double length = norm(options.normal);
  if (!std::isfinite(length) || length == 0.0)
    throw Error(fmt::format("the plane normal ({}, {}, {}) must be finite and non-zero",
                            options.normal.x, options.normal.y, options.normal.z));
  requirePositive("the plane spacing", options.spacing);
  requirePositive("the tool radius", options.toolRadius);
  const double scale = surfaceScale(surface);
  const double tolerance =
      options.chordalTolerance > 0.0 ? options.chordalTolerance : 1e-4 * std::max(scale, 1e-300);
  requirePositive("the chordal tolerance", tolerance);

  ContourPaths out;
  out.normal = options.normal / length;
  out.spacing = options.spacing;
  out.path.units = surface.units;
  out.path.toolRadius = options.toolRadius;
  // The surface lies in the convex hull of its control points: N . r spans at most their
  // range, so the planes k Delta with k in [ceil(lo / Delta), floor(hi / Delta)] are all
  // that can cut it.
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const BezierPatch& patch : surface.patches)
    for (const Vec3& p : patch.control) {
      lo = std::min(lo, dot(out.normal, p));
      hi = std::max(hi, dot(out.normal, p));
    }
  const double first = std::ceil(lo / options.spacing);
  const double last = std::floor(hi / options.spacing);
  if (last - first > 1e7)
    throw Error(fmt::format("the plane spacing {} gives {:.0f} planes across the surface; "
                            "more than 10 million is not a tool path",
                            options.spacing, last - first + 1));
  for (double kk = first; kk <= last; kk += 1.0) {
    const long long k = static_cast<long long>(kk);
    const double offset = kk * options.spacing;
    PlaneSection section = planeSection(surface, out.normal, offset, tolerance);
    out.stats.touchPoints += section.touchPoints.size();
    if (section.curves.empty()) continue;
    ++out.stats.planes;
    out.stats.components += section.components;
    for (const SectionCurve& curve : section.curves) {
      out.stats.contactLength += curveLength(curve);
      ToolPass pass;
      bool atStart = true;
      Vec3 previous;
      for (const SectionPoint& p : curve.points) {
        const Vec3 centre = p.point + options.toolRadius * upwardNormal(surface, p.patch, p.u, p.v);
        if (atStart) {
          pass.start = centre;
          atStart = false;
        } else {
          out.stats.centreLength += norm(centre - previous);
          pass.moves.push_back({MoveKind::line, centre, {}, ArcPlane::xy, true});
        }
        previous = centre;
      }
      if (!pass.moves.empty()) out.path.passes.push_back(std::move(pass));
    }
    out.sections.push_back({offset, k, std::move(section)});
  }
  if (out.sections.empty())
    throw Error(fmt::format(
        "no plane N . r = k * {} with N = ({}, {}, {}) cuts the surface (N . r spans [{}, {}])",
        options.spacing, out.normal.x, out.normal.y, out.normal.z, lo, hi));
  return out;
}

}  // namespace scallop
