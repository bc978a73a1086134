#include "scallop/paths/contour.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/parallel.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "paths/alignment.hpp"

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

// Per point, not per patch: a patch that folds over (a wall, an undercut) has both sides
// facing up somewhere, and the ball from above can only touch the upper one. Where the
// normal turns down the offset is inside the material and the drop envelope lifts it out.
Vec3 upwardNormal(const Surface& surface, std::size_t patch, double u, double v) {
  const Vec3 n = unitNormal(surface.patches.at(patch), u, v);
  return n.z < 0.0 ? -n : n;
}

void validatePlaneOffsets(const std::vector<double>& offsets, const char* what) {
  if (offsets.size() > static_cast<std::size_t>(kMaxPlanes))
    throw Error(fmt::format("{}: {} planes; more than 100,000 is not a tool path", what,
                            offsets.size()));
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    if (!std::isfinite(offsets[i]))
      throw Error(fmt::format("{}: offset {} is not finite ({})", what, i, offsets[i]));
    if (i > 0 && !(offsets[i] > offsets[i - 1]))
      throw Error(fmt::format("{}: offsets must increase strictly, got {} then {}", what,
                              offsets[i - 1], offsets[i]));
  }
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
    std::vector<detail::AlignmentPeak> samples;
    for (int i = 0; i <= kGrid; ++i)
      for (int j = 0; j <= kGrid; ++j) {
        const double u = double(i) / kGrid, v = double(j) / kGrid;
        samples.push_back({alignment(patch, m, u, v), u, v});
      }
    constexpr int kClimbed = 16;
    std::partial_sort(samples.begin(), samples.begin() + kClimbed, samples.end(),
                      [](const auto& a, const auto& b) { return a.value > b.value; });
    for (int s = 0; s < kClimbed; ++s) {
      const detail::AlignmentPeak peak = detail::climbAlignment(
          patch, m, samples[static_cast<std::size_t>(s)], 1.0 / kGrid, 1e-12);
      largest = std::max(largest, peak.value);
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

PlaneRange planeRange(const Surface& surface, const Vec3& unitNormal, double spacing,
                      const char* what) {
  PlaneRange range;
  range.lo = std::numeric_limits<double>::infinity();
  range.hi = -range.lo;
  for (const BezierPatch& patch : surface.patches)
    for (const Vec3& p : patch.control) {
      range.lo = std::min(range.lo, dot(unitNormal, p));
      range.hi = std::max(range.hi, dot(unitNormal, p));
    }
  range.first = std::ceil(range.lo / spacing);
  range.last = std::floor(range.hi / spacing);
  // At about 2,000 sections a second, 100,000 planes already take a minute; more is a
  // spacing typed in the wrong units, and would run for hours.
  if (range.last - range.first >= kMaxPlanes)
    throw Error(fmt::format("{} {} gives {:.0f} planes across the surface; more than 100,000 "
                            "is not a tool path (check the units)",
                            what, spacing, range.last - range.first + 1));
  return range;
}

ContourPaths contourPaths(const Surface& surface, const ContourOptions& options) {
  validateSurface(surface);
  const double length = norm(options.normal);
  if (!std::isfinite(length) || length == 0.0)
    throw Error(fmt::format("the plane normal ({}, {}, {}) must be finite and non-zero",
                            options.normal.x, options.normal.y, options.normal.z));
  validatePlaneOffsets(options.planeOffsets, "the plane offsets");
  const bool explicitOffsets = !options.planeOffsets.empty();
  if (!explicitOffsets) requirePositive("the plane spacing", options.spacing);
  requirePositive("the tool radius", options.toolRadius);
  if (!(options.depthTolerance >= 0.0) || !std::isfinite(options.depthTolerance))
    throw Error(fmt::format("the depth tolerance must be a finite number >= 0, got {}", options.depthTolerance));
  const double scale = surfaceScale(surface);
  const double tolerance =
      options.chordalTolerance > 0.0 ? options.chordalTolerance : 1e-4 * std::max(scale, 1e-300);
  requirePositive("the chordal tolerance", tolerance);

  ContourPaths out;
  out.normal = options.normal / length;
  out.spacing = options.spacing;
  out.path.units = surface.units;
  out.path.toolRadius = options.toolRadius;
  const PlaneRange range =
      explicitOffsets ? PlaneRange{options.planeOffsets.front(), options.planeOffsets.back(), 0.0,
                                   static_cast<double>(options.planeOffsets.size() - 1)}
                      : planeRange(surface, out.normal, options.spacing, "the plane spacing");
  const auto offsetAt = [&](double kk) {
    return explicitOffsets ? options.planeOffsets[static_cast<std::size_t>(kk)] : kk * options.spacing;
  };
  std::optional<SurfaceDistance> distance;
  if (options.dropEnvelope) distance.emplace(surface);
  // Each plane on its own (on every core): its section and passes, and the increments of
  // the lengths in the order the path is assembled, so that their sums come out the same,
  // bit for bit, for every thread count.
  struct PlaneWork {
    PlaneSection section;
    std::vector<ToolPass> passes;
    std::vector<double> contactLengths;  // per curve
    std::vector<double> centreSteps;     // per centre after each pass's first
  };
  const std::size_t planeCount = static_cast<std::size_t>(range.last - range.first + 1.0);
  std::vector<PlaneWork> planes(planeCount);
  parallelForEach(planeCount, threadCount(), [&](std::size_t i) {
    // The sections take about half of the stage, the lift to the envelope the rest.
    advanceStage(i, 2 * planeCount);  // polls the cancel; reports on the calling thread only
    const double kk = range.first + static_cast<double>(i);
    const double offset = offsetAt(kk);
    // The pass's band, half way to the neighbouring planes, for its run-on (envelope.hpp).
    RunOnBand band{out.normal, 0.0};
    double gap = 4.0 * options.toolRadius;
    if (kk > range.first) band.lo = 0.5 * (offsetAt(kk - 1.0) + offset), gap = std::min(gap, offset - offsetAt(kk - 1.0));
    if (kk < range.last) band.hi = 0.5 * (offset + offsetAt(kk + 1.0)), gap = std::min(gap, offsetAt(kk + 1.0) - offset);
    const double step = runOnStep(gap, options.toolRadius);
    PlaneWork& work = planes[i];
    work.section = planeSection(surface, out.normal, offset, tolerance);
    for (const SectionCurve& curve : work.section.curves) {
      work.contactLengths.push_back(curveLength(curve));
      ToolPass pass;
      bool atStart = true;
      Vec3 previous;
      for (const SectionPoint& p : curve.points) {
        const Vec3 normal = upwardNormal(surface, p.patch, p.u, p.v);
        const Vec3 centre = p.point + options.toolRadius * normal;
        if (atStart) {
          pass.start = centre;
          atStart = false;
        } else {
          work.centreSteps.push_back(norm(centre - previous));
          pass.moves.push_back({MoveKind::line, centre, {}, ArcPlane::xy, true});
        }
        previous = centre;
      }
      // With the drop envelope, an open pass runs on past the surface's edge while its ball
      // still finishes points near the edge (envelope.hpp, runOnPastEnd): where the planes
      // cross an edge obliquely and the surface slopes down to it, the edge between two pass
      // ends is otherwise left uncut (the simulated cut of paper-1 found scallops of 2.6 H
      // there with no run-on, 1.7 H with a fixed R / 4).
      if (distance && !curve.closed && !pass.moves.empty()) {
        const Vec3 penultimate = pass.moves.size() >= 2 ? pass.moves[pass.moves.size() - 2].end : pass.start;
        runPassOn(*distance, pass, pass.start - pass.moves.front().end, passEnd(pass) - penultimate,
                  options.toolRadius, band, step);
      }
      if (!pass.moves.empty()) work.passes.push_back(std::move(pass));
    }
  });
  for (std::size_t i = 0; i < planeCount; ++i) {
    PlaneWork& work = planes[i];
    out.stats.touchPoints += work.section.touchPoints.size();
    if (work.section.curves.empty()) continue;
    ++out.stats.planes;
    out.stats.components += work.section.components;
    for (const double curveContact : work.contactLengths) out.stats.contactLength += curveContact;
    for (const double step : work.centreSteps) out.stats.centreLength += step;
    for (ToolPass& pass : work.passes) out.path.passes.push_back(std::move(pass));
    const double kk = range.first + static_cast<double>(i);
    out.sections.push_back({offsetAt(kk), static_cast<long long>(kk), std::move(work.section)});
  }
  if (out.sections.empty())
    throw Error(fmt::format(
        "no plane N . r = k * {} with N = ({}, {}, {}) cuts the surface (N . r spans [{}, {}])",
        options.spacing, out.normal.x, out.normal.y, out.normal.z, range.lo, range.hi));
  if (options.dropEnvelope) {
    EnvelopeOptions envelope;
    envelope.depthTolerance = options.depthTolerance;
    envelope.stretchThreshold = options.stretchThreshold;
    envelope.sagTolerance = options.sagTolerance;
    const ProgressStage lifting(0.5, 1.0);  // the second half of the caller's stage
    out.path = liftToDropEnvelope(*distance, out.path, envelope, out.envelope);
    out.stats.centreLength = 0.0;
    for (const ToolPass& pass : out.path.passes) {
      Vec3 at = pass.start;
      for (const ToolMove& move : pass.moves) out.stats.centreLength += norm(move.end - at), at = move.end;
    }
  }
  return out;
}

}  // namespace scallop
