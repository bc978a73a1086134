#include "scallop/paths/linking.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/paths/envelope.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/paths/gouge.hpp"
#include "paths/clearance.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Sphere-tracing steps a direct link's proof may take (see below).
constexpr int kDirectLinkMaxSteps = 256;
// Moves a link over the drop envelope may have before a retract is preferred.
constexpr std::size_t kEnvelopeLinkMaxMoves = 2'000;

double resolved(const char* name, double value, double fallback) {
  if (!(std::isfinite(value) && value >= 0.0))
    throw Error(fmt::format("linking: option {} = {}: must be zero (the default) or a finite "
                            "positive number",
                            name, value));
  return value > 0.0 ? value : fallback;
}

bool isClosed(const ToolPass& pass) { return pass.moves.size() >= 2 && passEnd(pass) == pass.start; }

// A closed pass started at its k-th vertex (0: start, k: the end of move k - 1): the same
// loop, the same direction.
ToolPass rotated(const ToolPass& pass, std::size_t k) {
  if (k == 0) return pass;
  ToolPass out;
  out.retractBefore = pass.retractBefore;
  out.start = pass.moves[k - 1].end;
  out.moves.insert(out.moves.end(), pass.moves.begin() + static_cast<std::ptrdiff_t>(k),
                   pass.moves.end());
  out.moves.insert(out.moves.end(), pass.moves.begin(),
                   pass.moves.begin() + static_cast<std::ptrdiff_t>(k));
  return out;
}

void checkFinite(Vec3 p, std::size_t pass) {
  if (!(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)))
    throw Error(fmt::format("linking: pass {} has a position that is not finite", pass));
}

// A run of passes: a retracted head and the passes the strategy linked to it.
struct Unit {
  std::size_t first = 0;
  std::size_t count = 0;
};

// How a unit enters the order.
struct Entry {
  double distance = kInf;
  std::size_t unit = 0;
  bool reverse = false;
  std::size_t vertex = 0;  // closed single pass: where it starts
};

}  // namespace

LinkedPath linkToolPath(const Surface& surface, const ToolPath& path, const LinkOptions& options) {
  validateSurface(surface);
  const double radius = path.toolRadius;
  if (!(std::isfinite(radius) && radius > 0.0))
    throw Error(fmt::format("linking: the tool radius must be a positive number, got {}", radius));
  if (path.units != surface.units)
    throw Error(fmt::format("linking: the path's units ({}) differ from the surface's ({})",
                            unitsName(path.units), unitsName(surface.units)));
  if (options.direction != PassDirection::zigzag && options.direction != PassDirection::keep)
    throw Error(fmt::format("linking: option direction = {}: unknown",
                            static_cast<int>(options.direction)));
  if (!(options.maxOrderingWork > 0.0))
    throw Error(fmt::format("linking: option maxOrderingWork = {}: must be positive",
                            options.maxOrderingWork));
  const bool inch = surface.units == Units::inch;
  const double scale = std::max(surfaceScale(surface), 1e-300);
  LinkedPath out;
  out.stats.gougeAllowance = resolved("gougeAllowance", options.gougeAllowance, 1e-6 * scale);
  out.stats.clearance = resolved("clearance", options.clearance, inch ? 0.02 : 0.5);
  out.stats.plunge = resolved("plunge", options.plunge, inch ? 0.02 : 0.5);
  out.stats.directLinkMax = resolved("directLinkMax", options.directLinkMax, 4.0 * radius);
  out.path.units = path.units;
  out.path.toolRadius = radius;
  const std::size_t n = path.passes.size();
  out.stats.passes = n;
  for (std::size_t i = 0; i < n; ++i) {
    checkFinite(path.passes[i].start, i);
    for (const ToolMove& move : path.passes[i].moves) {
      checkFinite(move.end, i);
      if (move.kind == MoveKind::arc) checkFinite(move.center, i);
    }
  }
  if (n == 0) return out;

  // ---- Units and their order -----------------------------------------------------------
  std::vector<Unit> units;
  for (std::size_t i = 0; i < n; ++i) {
    if (i == 0 || path.passes[i].retractBefore) {
      units.push_back({i, 1});
    } else {
      ++units.back().count;
      ++out.stats.strategyLinks;
    }
  }
  out.stats.units = units.size();
  const auto single = [&](const Unit& u) { return u.count == 1; };
  const bool zigzag = options.direction == PassDirection::zigzag;
  std::vector<Entry> order{{0.0, 0, false, 0}};
  if (options.reorder && units.size() > 1) {
    double loopVertices = 0.0;
    for (const Unit& u : units)
      if (single(u) && isClosed(path.passes[u.first]))
        loopVertices += static_cast<double>(path.passes[u.first].moves.size());
    const double work = static_cast<double>(units.size()) * (static_cast<double>(units.size()) + loopVertices);
    if (work > options.maxOrderingWork)
      throw Error(fmt::format("linking: ordering {} runs of passes ({:.0f} loop vertices) takes "
                              "about {:.3g} comparisons, more than maxOrderingWork = {:.3g}; "
                              "raise it or keep the strategy's order (reorder = false)",
                              units.size(), loopVertices, work, options.maxOrderingWork));
    std::vector<bool> used(units.size(), false);
    used[0] = true;
    Vec3 at = passEnd(path.passes[units[0].first + units[0].count - 1]);
    for (std::size_t step = 1; step < units.size(); ++step) {
      checkCancelled();
      Entry best;
      for (std::size_t u = 0; u < units.size(); ++u) {
        if (used[u]) continue;
        const ToolPass& head = path.passes[units[u].first];
        const auto offer = [&](double d, bool reverse, std::size_t vertex) {
          if (d < best.distance) best = {d, u, reverse, vertex};
        };
        if (single(units[u]) && isClosed(head)) {
          // Every vertex, in the pass's own direction (a loop reversed offers no new entry).
          offer(norm(head.start - at), false, 0);
          for (std::size_t k = 1; k < head.moves.size(); ++k)
            offer(norm(head.moves[k - 1].end - at), false, k);
          continue;
        }
        offer(norm(head.start - at), false, 0);
        if (zigzag && single(units[u])) offer(norm(passEnd(head) - at), true, 0);
      }
      used[best.unit] = true;
      order.push_back(best);
      const Unit& chosen = units[best.unit];
      const ToolPass& last = path.passes[chosen.first + chosen.count - 1];
      if (best.reverse) {
        at = last.start;
      } else if (best.vertex > 0) {
        at = last.moves[best.vertex - 1].end;
      } else {
        at = passEnd(last);
      }
    }
  } else {
    for (std::size_t u = 1; u < units.size(); ++u) order.push_back({0.0, u, false, 0});
  }
  for (const Entry& e : order) {
    const Unit& u = units[e.unit];
    for (std::size_t i = u.first; i < u.first + u.count; ++i) {
      ToolPass pass = path.passes[i];
      if (e.reverse) {
        pass = reversedPass(pass);
        ++out.stats.reversedPasses;
      } else if (e.vertex > 0) {
        pass = rotated(pass, e.vertex);
        ++out.stats.rotatedLoops;
      }
      pass.retract.reset();
      out.path.passes.push_back(std::move(pass));
      out.origin.push_back(i);
      out.reversed.push_back(e.reverse);
    }
  }

  // ---- Links ---------------------------------------------------------------------------
  const double epsilon = out.stats.gougeAllowance;
  DistanceOptions distanceOptions;
  distanceOptions.tolerance = epsilon / 8.0;
  distanceOptions.maxCells = kLinkDistanceMaxCells;
  const SurfaceDistance distance(surface, distanceOptions);
  // The height bound is a surface point's height within this of the proven bound: tighter
  // than the clearance margin, which is what the traverse keeps anyway.
  const detail::HeightBound heights(surface, std::min(1e-4 * scale, out.stats.clearance / 4.0),
                                    1e-12 * scale);
  // Sphere tracing gives up where its margins fall below epsilon / 64 (raster's ways off:
  // slack / 64): the path creeps along its limit there.
  const double minStep = epsilon / 64.0;
  // The allowance at a pass end: its own depth (from the distance's upper bound, never
  // above the true depth) and epsilon.
  const auto allowance = [&](Vec3 c) {
    return std::max(radius - distance.closest(c).distance, 0.0) + epsilon;
  };
  // The vertical move between c and height `top` (either way) keeps depth <= allowed.
  const auto verticalClears = [&](Vec3 c, double top, double allowed) {
    return !(c.z < top) ||
           detail::segmentClears(distance, c, {c.x, c.y, top}, radius - allowed, radius, minStep);
  };
  // [e, s] lifted to the drop envelope, when that changes neither end and proves every move.
  const auto envelopeLink = [&](Vec3 e, Vec3 s) -> std::optional<std::vector<ToolMove>> {
    ToolPath link;
    link.units = surface.units;
    link.toolRadius = radius;
    link.passes.push_back(ToolPass{e, {ToolMove{MoveKind::line, s, {}, ArcPlane::xy, true}}, false, {}});
    EnvelopeOptions envelope;
    envelope.depthTolerance = epsilon;
    envelope.threads = 1;
    envelope.maxMoves = kEnvelopeLinkMaxMoves;
    EnvelopeReport report;
    ToolPath lifted;
    try {
      lifted = liftToDropEnvelope(distance, link, envelope, report);
    } catch (const Cancelled&) {
      throw;
    } catch (const Error&) {
      return std::nullopt;  // over its budget: a retract instead
    }
    const ToolPass& pass = lifted.passes.front();
    if (report.unprovenMoves > 0 || !(pass.start == e) || pass.moves.empty() || !(passEnd(pass) == s))
      return std::nullopt;
    return pass.moves;
  };
  std::vector<ToolPass>& passes = out.path.passes;
  out.linkMoves.assign(passes.size(), 0);
  for (std::size_t i = 0; i < passes.size(); ++i) {
    checkCancelled();
    ToolPass& pass = passes[i];
    if (i > 0 && !pass.retractBefore) continue;  // the strategy's own link
    const Vec3 s = pass.start;
    const double allowedS = allowance(s);
    if (i == 0) {
      const double top = heights.above({s.x, s.y}, {s.x, s.y}, radius) + radius;
      if (verticalClears(s, top, allowedS)) {
        const double height = s.z + out.stats.plunge;
        pass.retract = LocalRetract{height, height - s.z};  // d <= h - s.z despite rounding
        out.stats.firstPlungeShortened = true;
      }
      continue;
    }
    const Vec3 e = passEnd(passes[i - 1]);
    const double allowedE = allowance(e);
    const double length = norm(s - e);
    // A direct feed slides along the surface where its ends touch it, and the margins of
    // sphere tracing stay near epsilon there: give up after kDirectLinkMaxSteps steps (a
    // local retract is cheap) rather than creep.
    if (length <= out.stats.directLinkMax &&
        detail::segmentClears(distance, e, s, radius - std::max(allowedE, allowedS), radius,
                              minStep, kDirectLinkMaxSteps)) {
      pass.retractBefore = false;
      ++out.stats.directLinks;
      out.stats.directLinkLength += length;
      continue;
    }
    // The straight feed dips into the surface between two ends that touch it (two balls
    // beside an edge, on a crest): the feed over the drop envelope instead, every move
    // proven to cut no deeper than epsilon (envelope.hpp).
    if (length <= out.stats.directLinkMax) {
      if (std::optional<std::vector<ToolMove>> hugging = envelopeLink(e, s)) {
        Vec3 at = e;
        for (const ToolMove& move : *hugging) out.stats.directLinkLength += norm(move.end - at), at = move.end;
        pass.moves.insert(pass.moves.begin(), hugging->begin(), hugging->end());
        pass.start = e;
        out.linkMoves[i] = hugging->size();
        pass.retractBefore = false;
        ++out.stats.directLinks;
        ++out.stats.envelopeLinks;
        continue;
      }
    }
    const double top = heights.above({e.x, e.y}, {s.x, s.y}, radius) + radius;
    const double height = std::max({e.z, s.z, top + out.stats.clearance});
    if (verticalClears(e, top, allowedE) && verticalClears(s, top, allowedS)) {
      pass.retract = LocalRetract{height, std::min(out.stats.plunge, height - s.z)};
      ++out.stats.localRetracts;
    } else if (length <= out.stats.directLinkMax &&
               detail::segmentClears(distance, e, s, radius - std::max(allowedE, allowedS),
                                     radius, minStep)) {
      // No way up (an overhang above an end): the direct feed again, now with the full
      // budget of steps, before the unproven retract.
      pass.retractBefore = false;
      ++out.stats.directLinks;
      out.stats.directLinkLength += length;
    } else {
      ++out.stats.unprovenLinks;
    }
  }
  return out;
}

}  // namespace scallop
