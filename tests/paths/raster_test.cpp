// Raster paths against references written here: for every plane, the brute-force envelope of
// the lowest non-gouging ball centre over the section (as scallop_hull_test.cpp's), brute-
// force distances to the section's segments and end rays, arcs sampled by RS-274's own
// convention (G2 = clockwise seen from the positive axis, independently of how raster.cpp
// derives it), link clearances against dense surface points, and the best feed angle
// against a scan of 3600 angles with dense normals.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/paths/chain.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/error.hpp"
#include "scallop/paths/raster.hpp"
#include "scallop/geometry/surface.hpp"
#include "support/distance_reference.hpp"

namespace {

using scallop::ArcPlane;
using scallop::BezierPatch;
using scallop::MoveKind;
using scallop::Point2;
using scallop::RasterOptions;
using scallop::RasterPaths;
using scallop::Surface;
using scallop::ToolMove;
using scallop::ToolPass;
using scallop::Vec2;
using scallop::Vec3;

constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

// A bicubic graph patch like the paper's, p_jk = (k, j, z_jk) times `unit`, heights random
// in [-amplitude, amplitude] (fixed seed by the caller).
Surface randomGraphPatch(std::mt19937_64& rng, double unit, double amplitude) {
  std::uniform_real_distribution<double> z(-amplitude, amplitude);
  BezierPatch p;
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) p.control.push_back(unit * Vec3{double(k), double(j), z(rng)});
  Surface s;
  s.units = unit == 1.0 ? scallop::Units::inch : scallop::Units::millimetre;
  s.patches.push_back(p);
  return s;
}

// ---------------------------------------------------------------------------------------
// Arcs by the RS-274 convention
// ---------------------------------------------------------------------------------------

// In-plane coordinates (U, V) with U x V = the plane's positive axis, so counterclockwise
// in (U, V) is counterclockwise seen from that axis: G17 (x, y), G18 (z, x), G19 (y, z).
Vec2 inPlane(ArcPlane plane, Vec3 p) {
  switch (plane) {
    case ArcPlane::xy: return {p.x, p.y};
    case ArcPlane::zx: return {p.z, p.x};
    case ArcPlane::yz: return {p.y, p.z};
  }
  return {};
}
double acrossPlane(ArcPlane plane, Vec3 p) {
  return plane == ArcPlane::xy ? p.z : plane == ArcPlane::zx ? p.y : p.x;
}
Vec3 fromPlane(ArcPlane plane, Vec2 q, double n) {
  switch (plane) {
    case ArcPlane::xy: return {q.x, q.y, n};
    case ArcPlane::zx: return {q.y, n, q.x};
    case ArcPlane::yz: return {n, q.x, q.y};
  }
  return {};
}

struct ReferenceArc {
  double radius, startAngle, sweep;  // sweep > 0, in the move's turning sense
  bool clockwise;
};

ReferenceArc referenceArc(Vec3 from, const ToolMove& m) {
  const Vec2 a = inPlane(m.plane, from) - inPlane(m.plane, m.center);
  const Vec2 b = inPlane(m.plane, m.end) - inPlane(m.plane, m.center);
  const double a0 = std::atan2(a.y, a.x), a1 = std::atan2(b.y, b.x);
  double sweep = m.clockwise ? a0 - a1 : a1 - a0;
  while (sweep <= 0.0) sweep += 2.0 * kPi;
  while (sweep > 2.0 * kPi) sweep -= 2.0 * kPi;
  return {scallop::norm(a), a0, sweep, m.clockwise};
}

Vec3 arcPoint(const ToolMove& m, const ReferenceArc& g, double t) {
  const double angle = g.startAngle + (g.clockwise ? -1.0 : 1.0) * t * g.sweep;
  const Vec2 c = inPlane(m.plane, m.center);
  return fromPlane(m.plane, {c.x + g.radius * std::cos(angle), c.y + g.radius * std::sin(angle)},
                   acrossPlane(m.plane, m.center));
}

// Dense points along a move from `from` (both ends included).
std::vector<Vec3> sampleMove(Vec3 from, const ToolMove& m, int pieces) {
  std::vector<Vec3> out;
  if (m.kind == MoveKind::line) {
    for (int i = 0; i <= pieces; ++i) out.push_back(from + (double(i) / pieces) * (m.end - from));
  } else {
    const ReferenceArc g = referenceArc(from, m);
    for (int i = 0; i <= pieces; ++i) out.push_back(arcPoint(m, g, double(i) / pieces));
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// The plane's material: every section curve in (s, z), below it and its end rays
// ---------------------------------------------------------------------------------------

struct PlaneReference {
  std::vector<std::vector<Point2>> curves;

  // Distance to the curves' segments and the downward rays at their ends.
  double distance(Point2 p) const {
    double best = kInf;
    for (const auto& c : curves) {
      for (std::size_t i = 0; i + 1 < c.size(); ++i) {
        const Point2 a = c[i], b = c[i + 1];
        const double dx = b.x - a.x, dz = b.z - a.z, len2 = dx * dx + dz * dz;
        const double t =
            len2 > 0.0 ? std::clamp(((p.x - a.x) * dx + (p.z - a.z) * dz) / len2, 0.0, 1.0) : 0.0;
        best = std::min(best, std::hypot(p.x - a.x - t * dx, p.z - a.z - t * dz));
      }
      for (const Point2 v : {c.front(), c.back()})
        best = std::min(best, p.z >= v.z ? std::hypot(p.x - v.x, p.z - v.z) : std::abs(p.x - v.x));
    }
    return best;
  }

  // The lowest centre height at s at distance >= rho from the material: over vertices
  // within rho, v.z + sqrt(rho^2 - dx^2) (this covers the rays too), and over non-vertical
  // edges their offset line where the perpendicular's foot lies on the edge.
  double envelope(double s, double rho) const {
    double best = -kInf;
    for (const auto& c : curves) {
      for (const Point2 v : c) {
        // Within rounding of rho too: the path's ends are computed as s_0 - R.
        const double dx = std::min(std::abs(s - v.x), rho);
        if (std::abs(s - v.x) <= rho * (1.0 + 1e-14))
          best = std::max(best, v.z + std::sqrt((rho - dx) * (rho + dx)));
      }
      for (std::size_t i = 0; i + 1 < c.size(); ++i) {
        Point2 a = c[i], b = c[i + 1];
        if (a.x > b.x) std::swap(a, b);
        if (!(b.x > a.x)) continue;
        const double len = std::hypot(b.x - a.x, b.z - a.z);
        const double nx = -(b.z - a.z) / len, nz = (b.x - a.x) / len;  // upward normal
        const double t = (s - rho * nx - a.x) / (b.x - a.x);
        if (t >= 0.0 && t <= 1.0) best = std::max(best, a.z + t * (b.z - a.z) + rho * nz);
      }
    }
    return best;
  }

  bool hasVertexNear(Point2 p, double tol) const {
    for (const auto& c : curves)
      for (const Point2 v : c)
        if (std::hypot(v.x - p.x, v.z - p.z) <= tol) return true;
    return false;
  }
};

// One move of a pass in (s, z): a segment, or an arc given by its ends, centre and a point
// in its middle (the arc is the part of the circle on the midpoint's side of the chord).
struct Piece {
  bool arc = false;
  Point2 a, b, c, mid;
  double r = 0.0;
};

// The path's height at s: the highest point of any piece over s (vertical pieces count
// with their upper end, as scallop_hull.hpp's pathHeightAt).
double pathHeight(const std::vector<Piece>& pieces, double s) {
  double best = -kInf;
  for (const Piece& p : pieces) {
    if (!p.arc) {
      const double lo = std::min(p.a.x, p.b.x), hi = std::max(p.a.x, p.b.x);
      if (s < lo || s > hi) continue;
      best = std::max(best, hi > lo ? p.a.z + (s - p.a.x) / (p.b.x - p.a.x) * (p.b.z - p.a.z)
                                    : std::max(p.a.z, p.b.z));
      continue;
    }
    const double dx = s - p.c.x;
    if (std::abs(dx) > p.r * (1.0 + 1e-12)) continue;
    const double dz = std::sqrt(std::max(0.0, p.r * p.r - dx * dx));
    const auto side = [&](Point2 q) {
      return (p.b.x - p.a.x) * (q.z - p.a.z) - (p.b.z - p.a.z) * (q.x - p.a.x);
    };
    const double midSide = side(p.mid);
    for (const double z : {p.c.z + dz, p.c.z - dz}) {
      const Point2 q{s, z};
      const double qs = side(q);
      const bool nearEnd = std::hypot(q.x - p.a.x, q.z - p.a.z) < 1e-9 * p.r ||
                           std::hypot(q.x - p.b.x, q.z - p.b.z) < 1e-9 * p.r;
      if (nearEnd || qs * midSide > 0.0) best = std::max(best, z);
    }
  }
  return best;
}

// ---------------------------------------------------------------------------------------
// The checker
// ---------------------------------------------------------------------------------------

struct Checked {
  std::size_t arcs = 0;
  std::size_t links = 0;
  std::size_t samples = 0;
};

// Dense surface points, for the links' clearance.
std::vector<Vec3> surfacePoints(const Surface& s, int n) {
  std::vector<Vec3> out;
  for (const BezierPatch& p : s.patches)
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) out.push_back(scallop::point(p, double(i) / n, double(j) / n));
  return out;
}

double pointSegmentDistance3(Vec3 p, Vec3 a, Vec3 b) {
  const Vec3 ab = b - a;
  const double len2 = scallop::dot(ab, ab);
  const double t = len2 > 0.0 ? std::clamp(scallop::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return scallop::norm(p - (a + t * ab));
}

// Everything the contract promises about `r`, for feed angle `angle` and ball radius R.
// `polygonal`: arcs were polygonised to `arcTolerance` (feeds not along an axis).
Checked checkRaster(const Surface& surface, const RasterPaths& r, double angle, double R,
                    const std::string& label) {
  Checked out;
  const double scale = std::max(scallop::surfaceScale(surface), R);
  const double tol = 1e-9 * scale;
  const Vec3 d{std::cos(angle), std::sin(angle), 0.0};
  const Vec3 e{-std::sin(angle), std::cos(angle), 0.0};
  EXPECT_LT(scallop::norm(r.feedDirection - d), 1e-12) << label;
  EXPECT_LT(scallop::norm(r.planeNormal - e), 1e-12) << label;
  const bool alongX = std::abs(std::sin(angle)) < 1e-12;
  const bool alongY = std::abs(std::cos(angle)) < 1e-12;
  const bool polygonal = !alongX && !alongY;
  const double arcTolerance = 1e-4 * scallop::surfaceScale(surface);  // the default
  const std::vector<Vec3> dense = surfacePoints(surface, 120);

  EXPECT_EQ(r.path.passes.size(), r.passes.size()) << label;
  EXPECT_EQ(r.stats.planes, r.sections.size()) << label;
  std::size_t chains = 0;
  for (const auto& section : r.sections) {
    chains += section.chains.size();
    EXPECT_NEAR(section.offset, double(section.k) * r.spacing, 1e-12 * scale) << label;
  }
  EXPECT_EQ(chains, r.path.passes.size()) << label;

  double lengthSeen = 0.0;  // of the cutting moves
  for (std::size_t i = 0; i < r.path.passes.size(); ++i) {
    const ToolPass& pass = r.path.passes[i];
    const auto& info = r.passes[i];
    const auto& section = r.sections[info.section];
    const std::string where = label + " pass " + std::to_string(i) + " plane w = " +
                              std::to_string(section.offset);
    // Zigzag: the j-th plane runs toward increasing s for even j.
    EXPECT_EQ(info.reversed, info.section % 2 == 1) << where;
    PlaneReference ref;
    for (const auto& curve : section.section.curves) {
      ref.curves.emplace_back();
      for (const auto& p : curve.points) ref.curves.back().push_back({scallop::dot(d, p.point), p.point.z});
    }

    // Continuity with the previous pass and the link.
    Vec3 at = pass.start;
    if (info.linkMoves > 0) {
      ++out.links;
      if (i == 0) {
        ADD_FAILURE() << where << ": the first pass has a link";
        return out;
      }
      EXPECT_FALSE(pass.retractBefore) << where;
      const ToolPass& prev = r.path.passes[i - 1];
      const Vec3 prevEnd = prev.moves.empty() ? prev.start : prev.moves.back().end;
      EXPECT_EQ(pass.start, prevEnd) << where;  // bit for bit
      const Vec3 linkEnd = pass.moves[info.linkMoves - 1].end;  // the entry point
      const double floor = std::max(prevEnd.z, linkEnd.z);
      for (std::size_t k = 0; k < info.linkMoves; ++k) {
        const ToolMove& m = pass.moves[k];
        EXPECT_EQ(m.kind, MoveKind::line) << where;
        // Up at the previous end, across, down at the next start: never both horizontal
        // and vertical motion, across never below the higher end, the verticals never below
        // their own end.
        const bool vertical = m.end.x == at.x && m.end.y == at.y;
        EXPECT_TRUE(vertical || m.end.z == at.z) << where << " link move " << k;
        if (vertical) {
          const bool atPrevious = at.x == prevEnd.x && at.y == prevEnd.y;
          const bool atNext = at.x == linkEnd.x && at.y == linkEnd.y;
          EXPECT_TRUE(atPrevious || atNext) << where << " link move " << k;
          EXPECT_GE(std::min(at.z, m.end.z), atPrevious ? prevEnd.z : linkEnd.z)
              << where << " link move " << k << " goes below its end";
        } else {
          EXPECT_GE(m.end.z, floor) << where << " link move " << k << " goes below the ends";
        }
        EXPECT_GE(std::max(at.z, m.end.z), floor) << where << " link move " << k;
        // The ball clears every dense surface point along the move.
        double nearest = kInf;
        for (const Vec3& q : dense) nearest = std::min(nearest, pointSegmentDistance3(q, at, m.end));
        if (!vertical) {
          EXPECT_GE(nearest, R) << where << " link across move cuts the surface";
        }
        at = m.end;
      }
    } else {
      EXPECT_TRUE(pass.retractBefore) << where;
      // Retracted: the first pass, or not the first chain of its plane.
      const bool firstOfPlane = i == 0 || r.passes[i - 1].section != info.section;
      EXPECT_TRUE(i == 0 || !firstOfPlane) << where;
    }
    // The entry and the exit: at most one horizontal line each (their clearance is
    // PassEndsRiseWithoutCuttingDeeper's business).
    EXPECT_LE(info.entryMoves, 1u) << where;
    EXPECT_LE(info.exitMoves, 1u) << where;
    if (info.entryMoves > 1 || info.exitMoves > 1 ||
        pass.moves.size() <= info.linkMoves + info.entryMoves + info.exitMoves) {
      ADD_FAILURE() << where << ": no cutting moves between the entry and the exit";
      return out;
    }
    const auto expectHorizontalLine = [&](Vec3 from, const ToolMove& m, const char* what) {
      EXPECT_EQ(m.kind, MoveKind::line) << where << " " << what;
      EXPECT_EQ(m.end.z, from.z) << where << " " << what << " is not horizontal";
      EXPECT_GT(scallop::norm(m.end - from), 0.0) << where << " " << what << " is empty";
    };
    if (info.entryMoves == 1) {
      expectHorizontalLine(at, pass.moves[info.linkMoves], "entry");
      at = pass.moves[info.linkMoves].end;
    }
    const std::size_t cutEnd = pass.moves.size() - info.exitMoves;
    if (info.exitMoves == 1) expectHorizontalLine(pass.moves[cutEnd - 1].end, pass.moves.back(), "exit");

    // The cutting moves.
    const Vec3 cutStart = at;
    std::vector<Piece> pieces;
    double smin = kInf, smax = -kInf;
    for (std::size_t k = info.linkMoves + info.entryMoves; k < cutEnd; ++k) {
      const ToolMove& m = pass.moves[k];
      const std::string mw = where + " move " + std::to_string(k);
      Piece piece;
      piece.a = {scallop::dot(d, at), at.z};
      piece.b = {scallop::dot(d, m.end), m.end.z};
      if (m.kind == MoveKind::arc) {
        ++out.arcs;
        EXPECT_FALSE(polygonal) << mw << ": arcs only along an axis";
        EXPECT_EQ(m.plane, alongX ? ArcPlane::zx : ArcPlane::yz) << mw;
        // The plane's own coordinate is the same for both ends and the centre.
        EXPECT_EQ(acrossPlane(m.plane, at), acrossPlane(m.plane, m.center)) << mw;
        EXPECT_EQ(acrossPlane(m.plane, m.end), acrossPlane(m.plane, m.center)) << mw;
        const ReferenceArc g = referenceArc(at, m);
        EXPECT_NEAR(g.radius, R, 1e-9 * scale) << mw;
        EXPECT_NEAR(scallop::norm(m.end - m.center), R, 1e-9 * scale) << mw;
        // The hull's arcs roll over a convex vertex: less than half a turn.
        EXPECT_LE(g.sweep, kPi + 1e-9) << mw << " arc goes the long way round";
        piece.arc = true;
        piece.c = {scallop::dot(d, m.center), m.center.z};
        const Vec3 mid = arcPoint(m, g, 0.5);
        piece.mid = {scallop::dot(d, mid), mid.z};
        piece.r = g.radius;
        EXPECT_TRUE(ref.hasVertexNear(piece.c, 1e-9 * scale)) << mw << " centre not a vertex";
        lengthSeen += g.radius * g.sweep;
      } else {
        lengthSeen += scallop::norm(m.end - at);
      }
      pieces.push_back(piece);
      // Dense points: in the plane, never closer than R to the material, and (exact arcs)
      // never farther than R, (polygons) than R + the arc tolerance.
      for (const Vec3& p : sampleMove(at, m, m.kind == MoveKind::arc ? 64 : 8)) {
        ++out.samples;
        EXPECT_NEAR(scallop::dot(e, p), section.offset, tol) << mw;
        const Point2 q{scallop::dot(d, p), p.z};
        const double dist = ref.distance(q);
        EXPECT_GE(dist, R - tol) << mw << " at s = " << q.x << ", z = " << q.z;
        EXPECT_LE(dist, R + (polygonal ? arcTolerance : 0.0) + tol)
            << mw << " at s = " << q.x << ", z = " << q.z;
        smin = std::min(smin, q.x), smax = std::max(smax, q.x);
      }
      at = m.end;
    }
    if (pieces.empty()) {
      ADD_FAILURE() << where << ": no cutting moves";
      return out;
    }
    // Direction, and ends R beyond a section vertex at its height.
    const Point2 first = pieces.front().a, last = pieces.back().b;
    EXPECT_EQ(last.x < first.x, info.reversed) << where;
    const double outward = info.reversed ? -R : R;
    EXPECT_TRUE(ref.hasVertexNear({first.x + outward, first.z}, 1e-9 * scale)) << where;
    EXPECT_TRUE(ref.hasVertexNear({last.x - outward, last.z}, 1e-9 * scale)) << where;
    EXPECT_NEAR(scallop::dot(d, cutStart), first.x, tol) << where;
    // The height over dense s: the envelope itself (arcs), or on or above it (polygons).
    constexpr int kS = 400;
    for (int j = 0; j <= kS; ++j) {
      const double s = std::min(smax, smin + (smax - smin) * j / kS);
      // The band [envelope(R - tol), envelope(R + tol)], as scallop_hull_test.cpp: where the
      // path is vertical (the ends' quarter arcs) a rounding of s moves the height a lot.
      const double h = pathHeight(pieces, s);
      EXPECT_GE(h, ref.envelope(s, R - tol))
          << where << " at s = " << s << ": h - envelope = " << h - ref.envelope(s, R);
      if (!polygonal) {
        EXPECT_LE(h, ref.envelope(s, R + tol)) << where << " at s = " << s;
      }
    }
  }
  if (!polygonal) {
    EXPECT_NEAR(lengthSeen, r.stats.centreLength, 1e-9 * lengthSeen) << label;
  } else {
    EXPECT_GE(lengthSeen, r.stats.centreLength * (1.0 - 1e-12)) << label;  // circumscribed
    EXPECT_LE(lengthSeen, r.stats.centreLength * 1.01) << label;
  }
  double contact = 0.0;
  for (const auto& section : r.sections)
    for (const auto& curve : section.section.curves) contact += scallop::curveLength(curve);
  EXPECT_NEAR(contact, r.stats.contactLength, 1e-12 * contact) << label;
  return out;
}

// The scallop hull's paths as they are, exact in their planes (the stage the checker above
// judges); the drop envelope on top is tests/paths/envelope_test.cpp's.
RasterPaths run(const Surface& s, double angle, double R, double spacing) {
  RasterOptions o;
  o.dropEnvelope = false;
  o.angleRad = angle;
  o.toolRadius = R;
  o.spacing = spacing;
  return scallop::rasterPaths(s, o);
}

// ---------------------------------------------------------------------------------------
// Tests
// ---------------------------------------------------------------------------------------

TEST(Raster, PaperSurfacesAtSeveralAngles) {
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = scallop::exampleSurface(name);
    for (const double deg : {0.0, 90.0, 30.0, 137.0, 180.0, 270.0}) {
      const RasterPaths r = run(s, deg * kDeg, 0.25, 0.15);
      const std::string label = std::string(name) + " at " + std::to_string(deg) + " deg";
      const Checked c = checkRaster(s, r, deg * kDeg, 0.25, label);
      EXPECT_GT(r.stats.planes, 15u) << label;
      EXPECT_EQ(c.links + 1, r.path.passes.size()) << label;  // one chain per plane here
      if (std::fmod(deg, 90.0) == 0.0) {
        EXPECT_GT(c.arcs, 0u) << label;
      }
    }
  }
}

TEST(Raster, RandomGraphPatchesInchesAndMillimetres) {
  std::mt19937_64 rng(42);
  for (const double unit : {1.0, 25.4}) {
    for (int trial = 0; trial < 3; ++trial) {
      const Surface s = randomGraphPatch(rng, unit, 1.0);
      for (const double deg : {0.0, 90.0, 30.0, 137.0}) {
        const double R = 0.25 * unit;
        const RasterPaths r = run(s, deg * kDeg, R, 0.2 * unit);
        const std::string label = "unit " + std::to_string(unit) + " trial " +
                                  std::to_string(trial) + " at " + std::to_string(deg) + " deg";
        checkRaster(s, r, deg * kDeg, R, label);
        EXPECT_EQ(r.unclearedEnds, 0u) << label;
      }
    }
  }
}

// Each pass's ends: from the hull path's end c, the exit (a horizontal move, then straight
// up to the clear height, the highest control point + R) never brings the ball deeper into
// the surface than max(its depth at c, 0) + the slack; the entry likewise,
// backwards. Depths R - dist from the test's own distance reference (dense sampling and a
// pattern search: it never underestimates a distance, so it never overstates a depth away
// from c), sampled every R / 10 along the way. At oblique feeds the paper's surfaces have
// ends where rising straight from c would cut in deeper by far more than the tolerance (the
// gap the exits close): the test shows they exist, so the check is not vacuous.
TEST(Raster, PassEndsRiseWithoutCuttingDeeper) {
  const double R = 0.25;
  std::size_t straightWouldCutInAll = 0;
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = scallop::exampleSurface(name);
    // The contract's slack: max(chordal tolerance, R / 256).
    const double slack = std::max(1e-4 * scallop::surfaceScale(s), R / 256.0);
    double top = -kInf;
    for (const auto& patch : s.patches)
      for (const Vec3& p : patch.control) top = std::max(top, p.z);
    const double clearHeight = top + R;
    const auto depth = [&](Vec3 c) {
      return R - scallop::reference::referenceDistance(s, c, 24, 4).refined;
    };
    for (const double deg : {30.0, 137.0}) {
      const std::string label = std::string(name) + " at " + std::to_string(deg) + " deg";
      const RasterPaths r = run(s, deg * kDeg, R, 0.3);
      EXPECT_EQ(r.unclearedEnds, 0u) << label;
      std::size_t moved = 0, straightWouldCut = 0;
      double worstExcess = -kInf;
      double offLength = 0.0;  // links, entries and exits
      // Checks the way off from c through `to` (c itself: straight up); returns how much
      // deeper than allowed rising straight from c would cut.
      const auto checkEnd = [&](Vec3 c, Vec3 to, const std::string& where) {
        const double limit = std::max(depth(c), 0.0) + slack;
        const auto worstAlong = [&](Vec3 a, Vec3 b) {
          const int n = std::max(1, static_cast<int>(std::ceil(scallop::norm(b - a) / (R / 10))));
          double worst = -kInf;
          for (int k = 1; k <= n; ++k) worst = std::max(worst, depth(a + (b - a) * (double(k) / n)));
          return worst;
        };
        const Vec3 up{to.x, to.y, std::max(clearHeight, to.z)};
        const double along = std::max(worstAlong(c, to), worstAlong(to, up));
        worstExcess = std::max(worstExcess, along - limit);
        EXPECT_LE(along, limit) << label << " " << where << " cuts deeper on its way off";
        if (to == c) return;
        ++moved;
        const double straight = worstAlong(c, {c.x, c.y, std::max(clearHeight, c.z)});
        if (straight > limit + 0.01) ++straightWouldCut;
      };
      for (std::size_t i = 0; i < r.path.passes.size(); ++i) {
        const ToolPass& pass = r.path.passes[i];
        const auto& info = r.passes[i];
        const std::string where = "pass " + std::to_string(i);
        Vec3 at = pass.start;
        for (std::size_t k = 0; k < info.linkMoves; ++k) {
          offLength += scallop::norm(pass.moves[k].end - at);
          at = pass.moves[k].end;
        }
        const Vec3 entry = at;
        const Vec3 hullStart = info.entryMoves == 1 ? pass.moves[info.linkMoves].end : entry;
        const std::size_t n = pass.moves.size();
        const Vec3 exit = pass.moves.back().end;
        const Vec3 hullEnd = info.exitMoves == 1 ? pass.moves[n - 2].end : exit;
        offLength += scallop::norm(hullStart - entry) + scallop::norm(exit - hullEnd);
        checkEnd(hullStart, entry, where + " entry");
        checkEnd(hullEnd, exit, where + " exit");
      }
      EXPECT_NEAR(offLength, r.linkLength, 1e-9 * offLength) << label;
      EXPECT_GT(moved, 0u) << label;
      straightWouldCutInAll += straightWouldCut;
      std::printf("[ raster   ] %s: %zu of %zu ends move away first (%zu where rising straight "
                  "would cut > 0.01 deeper); worst depth over the limit %.2g\n",
                  label.c_str(), moved, 2 * r.path.passes.size(), straightWouldCut, worstExcess);
    }
  }
  EXPECT_GT(straightWouldCutInAll, 0u) << "no end where rising straight would cut in";
}

// Two patches with a gap between them along the feed: one chain per plane when the gap is
// narrower than the ball (bridged, the hull sees both sides), two passes, the second
// retracted, when it is wider.
TEST(Raster, GapsInTheFootprint) {
  std::mt19937_64 rng(7);
  for (const double gap : {0.3, 1.0}) {
    Surface s = randomGraphPatch(rng, 1.0, 0.5);
    Surface t = randomGraphPatch(rng, 1.0, 0.5);
    for (Vec3& p : t.patches[0].control) p.x += 3.0 + gap;
    s.patches.push_back(t.patches[0]);
    for (const double deg : {0.0, 180.0, 10.0}) {
      const RasterPaths r = run(s, deg * kDeg, 0.25, 0.25);
      const std::string label = "gap " + std::to_string(gap) + " at " + std::to_string(deg);
      checkRaster(s, r, deg * kDeg, 0.25, label);
      std::size_t twoChains = 0;
      for (const auto& section : r.sections) twoChains += section.chains.size() == 2;
      if (gap < 0.5) {
        EXPECT_EQ(twoChains, 0u) << label;
      } else {
        EXPECT_GT(twoChains, 0u) << label;
      }
    }
  }
}

// A wall that folds over along x (control x 0, 4, -2, 2 along v while z rises): the
// sections y = const are S-shaped, and the planes x = const meet two sheets. The named
// (u, v) must be on the surface, in the plane, and where x turns (x_v changes sign).
TEST(Raster, NotAGraphNamesWhere) {
  BezierPatch p;
  const double xs[4] = {0.0, 4.0, -2.0, 2.0};
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) p.control.push_back({xs[k], double(j), double(k)});
  Surface s;
  s.patches.push_back(p);
  for (const double deg : {0.0, 90.0, 180.0}) {
    try {
      run(s, deg * kDeg, 0.25, 0.5);
      ADD_FAILURE() << "no error at " << deg;
    } catch (const scallop::Error& error) {
      const std::string m = error.what();
      EXPECT_NE(m.find("not a graph over the raster direction"), std::string::npos) << m;
      EXPECT_NE(m.find("plane e . r = "), std::string::npos) << m;
      EXPECT_NE(m.find("patch 0 (u, v) = ("), std::string::npos) << m;
      EXPECT_NE(m.find("point ("), std::string::npos) << m;
      double u = -1.0, v = -1.0, x = 0.0, y = 0.0, z = 0.0, w = 0.0;
      const auto at = m.find("(u, v) = (");
      const auto plane = m.find("plane e . r = ");
      ASSERT_NE(at, std::string::npos) << m;
      ASSERT_EQ(std::sscanf(m.c_str() + plane, "plane e . r = %lf", &w), 1) << m;
      ASSERT_EQ(std::sscanf(m.c_str() + at, "(u, v) = (%lf, %lf), point (%lf, %lf, %lf)", &u, &v,
                            &x, &y, &z),
                5)
          << m;
      const Vec3 e{-std::sin(deg * kDeg), std::cos(deg * kDeg), 0.0};
      const Vec3 r = scallop::point(p, u, v);
      EXPECT_LT(scallop::norm(r - Vec3{x, y, z}), 1e-5) << m;
      EXPECT_NEAR(scallop::dot(e, r), w, 1e-5) << m;
      if (deg == 0.0) {
        EXPECT_NE(m.find("turns back"), std::string::npos) << m;
        EXPECT_LT(scallop::derivativeV(p, u, std::max(0.0, v - 0.05)).x *
                      scallop::derivativeV(p, u, std::min(1.0, v + 0.05)).x,
                  0.0)
            << m;
      }
    }
  }
}

// A patch whose v-curves are closed teardrops in (x, z): every section y = const is a loop.
TEST(Raster, ClosedSectionIsNotAGraph) {
  BezierPatch p;
  const Vec2 xz[4] = {{0.0, 0.0}, {3.0, 3.0}, {-3.0, 3.0}, {0.0, 0.0}};
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) p.control.push_back({xz[k].x, double(j), xz[k].y});
  Surface s;
  s.patches.push_back(p);
  try {
    run(s, 0.0, 0.25, 0.5);
    ADD_FAILURE() << "no error";
  } catch (const scallop::Error& error) {
    const std::string m = error.what();
    EXPECT_NE(m.find("not a graph over the raster direction"), std::string::npos) << m;
    EXPECT_TRUE(m.find("closed loop") != std::string::npos ||
                m.find("turns back") != std::string::npos)
        << m;
    EXPECT_NE(m.find("patch 0 (u, v) = ("), std::string::npos) << m;
  }
}

// alpha(a) by brute force: normals on a dense grid, 3600 angles in [0, pi).
TEST(Raster, BestAngleAgainstScan) {
  std::mt19937_64 rng(3);
  std::vector<std::pair<std::string, Surface>> surfaces = {
      {"paper-1", scallop::exampleSurface("paper-1")},
      {"paper-2", scallop::exampleSurface("paper-2")},
      {"random", randomGraphPatch(rng, 1.0, 1.0)}};
  for (const auto& [name, s] : surfaces) {
    std::vector<Vec3> normals;
    constexpr int kN = 150;
    for (const BezierPatch& p : s.patches)
      for (int i = 0; i <= kN; ++i)
        for (int j = 0; j <= kN; ++j)
          normals.push_back(scallop::unitNormal(p, double(i) / kN, double(j) / kN));
    const auto alpha = [&](double a) {
      double worst = 0.0;
      for (const Vec3& n : normals) worst = std::max(worst, std::abs(-std::sin(a) * n.x + std::cos(a) * n.y));
      return std::acos(std::min(1.0, worst));
    };
    double bestScan = 0.0, bestScanAngle = 0.0;
    for (int i = 0; i < 3600; ++i) {
      const double a = i * kPi / 3600.0;
      const double v = alpha(a);
      if (v > bestScan) bestScan = v, bestScanAngle = a;
    }
    const double best = scallop::bestRasterAngle(s);
    EXPECT_GE(best, 0.0) << name;
    EXPECT_LT(best, kPi) << name;
    EXPECT_GE(alpha(best), bestScan - 0.05 * kDeg)
        << name << ": best " << best / kDeg << " deg, scan " << bestScanAngle / kDeg << " deg";
    // The reported alpha is a proven lower bound: never above the sampled one.
    const double proven =
        scallop::minimumAngleBound(s, {-std::sin(best), std::cos(best), 0.0});
    EXPECT_LE(proven, alpha(best) + 1e-12) << name;
    EXPECT_GE(proven, alpha(best) - 0.05 * kDeg) << name;
  }
}

TEST(Raster, BestAngleOptionAndScallopHeight) {
  const Surface s = scallop::exampleSurface("paper-1");
  RasterOptions o;
  o.bestAngle = true;
  o.toolRadius = 0.25;
  o.scallopHeight = 0.001;
  o.dropEnvelope = false;
  const RasterPaths r = scallop::rasterPaths(s, o);
  EXPECT_EQ(r.angleRad, scallop::bestRasterAngle(s));
  EXPECT_GT(r.alphaRad, 0.0);
  EXPECT_DOUBLE_EQ(r.spacing, scallop::spacingForScallopHeight(0.25, 0.001, r.alphaRad));
  checkRaster(s, r, r.angleRad, 0.25, "best angle");
}

TEST(Raster, BadOptionsNameTheValue) {
  const Surface s = scallop::exampleSurface("paper-1");
  const auto expectError = [&](RasterOptions o, const std::string& needle) {
    try {
      scallop::rasterPaths(s, o);
      ADD_FAILURE() << "no error for " << needle;
    } catch (const scallop::Error& error) {
      EXPECT_NE(std::string(error.what()).find(needle), std::string::npos) << error.what();
    }
  };
  RasterOptions good;
  good.toolRadius = 0.25;
  good.spacing = 0.1;
  RasterOptions o = good;
  o.toolRadius = 0.0;
  expectError(o, "tool radius must be a positive number, got 0");
  o.toolRadius = -0.5;
  expectError(o, "got -0.5");
  o.toolRadius = std::nan("");
  expectError(o, "tool radius must be a positive number, got nan");
  o = good;
  o.spacing = -0.1;
  expectError(o, "step-over (plane spacing) must be a positive number, got -0.1");
  o.spacing = 0.0;
  expectError(o, "got 0");
  o.spacing = kInf;
  expectError(o, "got inf");
  o = good;
  o.angleRad = std::nan("");
  expectError(o, "feed angle must be a finite number of radians, got nan");
  o = good;
  o.scallopHeight = 0.01;
  expectError(o, "not both");
  o = good;
  o.spacing = 0.0;
  o.scallopHeight = 0.3;
  expectError(o, "scallop height 0.3 must be smaller than the tool radius 0.25");
  o = good;
  o.chordalTolerance = -1e-3;
  expectError(o, "chordal tolerance must be zero (the default) or a positive number, got -0.001");
  o = good;
  o.arcTolerance = std::nan("");
  expectError(o, "arc tolerance must be zero (the default) or a positive number, got nan");
  // No plane k * 10 meets a surface lying at 0.5 <= y <= 2.5.
  Surface small = scallop::exampleSurface("paper-1");
  for (Vec3& p : small.patches[0].control) p.y = 0.5 + 2.0 * p.y / 3.0;
  o = good;
  o.spacing = 10.0;
  try {
    scallop::rasterPaths(small, o);
    ADD_FAILURE() << "no error for planes missing the surface";
  } catch (const scallop::Error& error) {
    EXPECT_NE(std::string(error.what()).find("cuts the surface"), std::string::npos) << error.what();
  }
}

// The figures for the report: paper-1 and paper-2, R = 0.25 in, at angle 0 and at the best
// angle, with a step-over of 0.05 in and with the step-over for a scallop height of 0.001 in
// (where the best angle's larger alpha pays).
TEST(Raster, PaperFigures) {
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = scallop::exampleSurface(name);
    for (const bool fixed : {true, false})
    for (const bool best : {false, true}) {
      RasterOptions o;
      o.toolRadius = 0.25;
      (fixed ? o.spacing : o.scallopHeight) = fixed ? 0.05 : 0.001;
      o.bestAngle = best;
      o.dropEnvelope = false;  // the hull stage's figures (the envelope's: scallop-bench)
      const auto t0 = std::chrono::steady_clock::now();
      const RasterPaths r = scallop::rasterPaths(s, o);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      std::size_t chains = 0;
      for (const auto& section : r.sections) chains += section.chains.size();
      std::printf("[ figures  ] %s angle %.4f deg (alpha %.4f deg), step-over %.5f in: %zu planes, "
                  "%zu chains, centre %.3f in, links %.3f in, contact %.3f in, %.0f ms\n",
                  name, r.angleRad / kDeg, r.alphaRad / kDeg, r.spacing, r.stats.planes, chains,
                  r.stats.centreLength, r.linkLength, r.stats.contactLength, ms);
      EXPECT_EQ(chains, r.stats.planes) << name;
      EXPECT_GT(r.stats.centreLength, 0.0) << name;
    }
  }
}

}  // namespace
