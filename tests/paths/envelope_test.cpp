// The drop envelope (envelope.hpp) and the segment clearance test under it (gouge.hpp),
// judged by tests/support/distance_reference.hpp: every patch sampled on a grid and refined by a
// derivative-free pattern search, written independently of gouge.cpp. Its distance is
// attained by a surface point, so it is never below the true distance.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "support/distance_reference.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/paths/envelope.hpp"
#include "scallop/error.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/raster.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

double referenceDistance(const Surface& s, Vec3 p) {
  return reference::referenceDistance(s, p, 20, 3).refined;
}

// Points along a move from `from`: the ends and `inner` points between (arcs along the arc).
std::vector<Vec3> pointsOn(Vec3 from, const ToolMove& move, int inner) {
  std::vector<Vec3> out;
  for (int i = 0; i <= inner + 1; ++i) {
    const double t = static_cast<double>(i) / (inner + 1);
    if (move.kind == MoveKind::line) {
      out.push_back(from + t * (move.end - from));
      continue;
    }
    const Vec3 a = toArcPlane(move.plane, from - move.center);
    const Vec3 b = toArcPlane(move.plane, move.end - move.center);
    double sweep = std::atan2(b.y, b.x) - std::atan2(a.y, a.x);
    const double turn = 2.0 * std::numbers::pi;
    if (move.clockwise) {
      while (sweep >= 0.0) sweep -= turn;
    } else {
      while (sweep <= 0.0) sweep += turn;
    }
    const double angle = std::atan2(a.y, a.x) + t * sweep;
    const double r = std::hypot(a.x, a.y);
    out.push_back(move.center + fromArcPlane(move.plane, {r * std::cos(angle), r * std::sin(angle), a.z}));
  }
  return out;
}

// Two bicubic graph patches meeting along x = 3 at a crease (their slopes differ there), with
// random heights: concave or convex creases, concave regions tighter than a large ball.
Surface creasedSurface(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> z(-0.6, 0.6), slope(-0.8, 0.8);
  const double a = slope(rng), b = slope(rng);
  Surface s;
  double shared[4];
  for (double& h : shared) h = z(rng);
  for (int part = 0; part < 2; ++part) {
    BezierPatch p;
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) {
        const int column = part == 0 ? k : 3 + k;
        double height = column == 3 ? shared[j] : z(rng) * 0.5 + (part == 0 ? a : b) * (column - 3);
        p.control.push_back({double(column), double(j), height});
      }
    }
    s.patches.push_back(p);
  }
  return s;
}

// ---------------------------------------------------------------------------------------
// Segment clearance against the reference
// ---------------------------------------------------------------------------------------

// Random short and long segments near the paper's surfaces and random creased ones: a proof
// holds against the reference at 16 points along the segment (the reference can only
// overstate the distance, so it can only miss a false proof between its samples: a fine
// grid makes that rare, and the test counts on none); a violation names a surface point
// that really is nearer than the clearance.
TEST(SegmentClearance, ProofsHoldAndViolationsAreReal) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> unit(0.0, 1.0), offset(-0.4, 0.4), length(0.001, 0.6);
  std::size_t proven = 0, violated = 0, undecided = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const Surface s = trial % 3 == 0 ? exampleSurface("paper-1")
                      : trial % 3 == 1 ? exampleSurface("paper-2")
                                       : creasedSurface(rng);
    const SurfaceDistance distance(s);
    // Above a random surface point, by about the clearance, along a random direction.
    const BezierPatch& patch = s.patches[rng() % s.patches.size()];
    const Vec3 base = point(patch, unit(rng), unit(rng));
    const double clearance = 0.05 + 0.4 * unit(rng);
    const Vec3 a = base + Vec3{offset(rng), offset(rng), clearance + offset(rng) * 0.5};
    const double theta = 2.0 * std::numbers::pi * unit(rng);
    const double phi = 0.3 * (unit(rng) - 0.5);
    const Vec3 b = a + length(rng) * Vec3{std::cos(theta) * std::cos(phi), std::sin(theta) * std::cos(phi), std::sin(phi)};
    const SegmentClearance test = distance.segmentClearance(a, b, clearance);
    const std::string where = "trial " + std::to_string(trial);
    if (test.verdict == Clearance::proven) {
      ++proven;
      for (int i = 0; i <= 16; ++i) {
        const Vec3 c = a + (i / 16.0) * (b - a);
        EXPECT_GE(referenceDistance(s, c), clearance - 1e-12) << where << " at " << i;
      }
    } else if (test.verdict == Clearance::violated) {
      ++violated;
      // The point is on the surface (within rounding) and nearer than the clearance.
      const Vec3 onSurface = point(s.patches[test.patch], test.u, test.v);
      EXPECT_LE(norm(onSurface - test.point), 1e-12 * 8.0) << where;
      const Vec3 ab = b - a;
      const double t = std::clamp(dot(test.point - a, ab) / dot(ab, ab), 0.0, 1.0);
      EXPECT_LT(norm(test.point - (a + t * ab)), clearance) << where;
    } else {
      ++undecided;
    }
  }
  std::printf("[          ] %zu proven, %zu violated, %zu undecided\n", proven, violated, undecided);
  EXPECT_GT(proven, 150u);
  EXPECT_GT(violated, 150u);
  EXPECT_EQ(undecided, 0u);
}

// The halved cells a thread keeps across queries (gouge.cpp's cell store) change nothing:
// queries in small steps along a line (as the drop envelope's proofs along a pass), by one
// engine and a copy of it (which shares its cells), then by two engines in turn (each
// flushing the other's cells), give bit for bit what a fresh engine (an empty store) gives,
// for segment clearances, proven and refuted, and for closest points.
TEST(SegmentClearance, KeptCellsGiveTheSameBits) {
  const Surface surfaces[2] = {exampleSurface("paper-1"), exampleSurface("paper-2")};
  const SurfaceDistance engines[2] = {SurfaceDistance(surfaces[0]), SurfaceDistance(surfaces[1])};
  const SurfaceDistance copy = engines[0];
  struct Query {
    int surface;
    Vec3 a, b;
    double clearance;
  };
  std::vector<Query> queries;
  for (int k = 0; k < 2; ++k) {
    const Surface& s = surfaces[k];
    for (int i = 0; i < 300; ++i) {
      const BezierPatch& patch = s.patches[static_cast<std::size_t>(i / 100) % s.patches.size()];
      const double u = 0.2 + 0.006 * (i % 100);
      Vec3 up = unitNormal(patch, u, 0.5);
      if (up.z < 0.0) up = -up;
      const Vec3 a = point(patch, u, 0.5) + 0.25 * up;  // touching, about
      const double clearance = 0.25 + (i % 3 == 0 ? 1e-6 : -1e-5);  // refuted or proven
      queries.push_back({k, a, a + Vec3{0.004, 0.001, 0.0}, clearance});
      queries.push_back({k, a, a + Vec3{0.0, 0.0, 0.5}, clearance});  // straight up
    }
  }
  struct Answer {
    SegmentClearance segment;
    ClosestPoint closest;
  };
  const auto ask = [&](const SurfaceDistance& engine, const Query& q) {
    return Answer{engine.segmentClearance(q.a, q.b, q.clearance), engine.closest(q.b)};
  };
  std::vector<Answer> kept, turns, fresh;
  for (std::size_t i = 0; i < queries.size(); ++i) {  // one surface after the other
    const Query& q = queries[i];
    kept.push_back(ask(q.surface == 0 && i % 2 == 1 ? copy : engines[q.surface], q));
  }
  for (std::size_t i = 0; i < queries.size() / 2; ++i) {  // the two surfaces in turn
    for (const std::size_t j : {i, i + queries.size() / 2}) turns.push_back(ask(engines[queries[j].surface], queries[j]));
  }
  for (const Query& q : queries) fresh.push_back(ask(SurfaceDistance(surfaces[q.surface]), q));
  const auto same = [](const Answer& x, const Answer& y, const std::string& where) {
    EXPECT_EQ(x.segment.verdict, y.segment.verdict) << where;
    EXPECT_EQ(x.segment.distance, y.segment.distance) << where;
    EXPECT_EQ(x.segment.patch, y.segment.patch) << where;
    EXPECT_EQ(x.segment.u, y.segment.u) << where;
    EXPECT_EQ(x.segment.v, y.segment.v) << where;
    EXPECT_EQ(x.segment.cells, y.segment.cells) << where;
    EXPECT_EQ(x.closest.distance, y.closest.distance) << where;
    EXPECT_EQ(x.closest.lowerBound, y.closest.lowerBound) << where;
    EXPECT_EQ(x.closest.u, y.closest.u) << where;
    EXPECT_EQ(x.closest.v, y.closest.v) << where;
    EXPECT_EQ(x.closest.cells, y.closest.cells) << where;
  };
  std::size_t cells = 0, proven = 0;
  for (std::size_t i = 0; i < queries.size(); ++i) {
    same(kept[i], fresh[i], "query " + std::to_string(i));
    const std::size_t half = queries.size() / 2;
    same(turns[i], fresh[i % 2 == 0 ? i / 2 : half + i / 2], "in turn, query " + std::to_string(i));
    cells += kept[i].segment.cells;
    proven += kept[i].segment.verdict == Clearance::proven ? 1 : 0;
  }
  EXPECT_GT(cells, 20 * queries.size());  // deep enough to halve below the trees, often
  EXPECT_GT(proven, queries.size() / 4);
  EXPECT_LT(proven, queries.size());
}

// A segment lying exactly R from a plane, rolling along it: proven at R - 1e-9, refuted at
// R + 1e-9 (the bound is second-order sharp, not a Lipschitz cone).
TEST(SegmentClearance, SharpOnAPlane) {
  BezierPatch plane{1, 1, {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}}};
  const SurfaceDistance distance(Surface{Units::inch, {plane}});
  const Vec3 a{0.2, 0.3, 0.25}, b{0.8, 0.6, 0.25};
  EXPECT_EQ(distance.segmentClearance(a, b, 0.25 - 1e-9).verdict, Clearance::proven);
  EXPECT_EQ(distance.segmentClearance(a, b, 0.25 + 1e-9).verdict, Clearance::violated);
}

// ---------------------------------------------------------------------------------------
// The lifted paths against the reference
// ---------------------------------------------------------------------------------------

struct Judged {
  std::size_t samples = 0;
  double deepest = -1.0;       // max R - reference distance over the samples
  double loosestVertex = 0.0;  // max reference distance - R over the input vertices
};

// Every move sampled (ends and `inner` points between): the reference depth at most eps (and
// a rounding hair); the ball over each input vertex (moveMap) touches: its reference
// distance at most R + eps + `slack` (the input's own distance beyond R where it was not
// lifted: a polygonised arc's vertex stands up to the arc tolerance off); the vertex kept
// its (x, y); the shank above each output vertex clear (the ball at 4 heights up to the top).
// `cutting(pass, move)` says which input vertices are on the surface (raster's links, ways on
// and off stand above it by design).
template <typename Cutting>
Judged judge(const Surface& s, const ToolPath& input, const ToolPath& lifted,
             const std::vector<std::vector<std::size_t>>& moveMap, double eps, double slack,
             std::size_t passStride, const std::string& label, const Cutting& cutting) {
  Judged out;
  const double R = lifted.toolRadius;
  double top = -1e300;
  for (const BezierPatch& p : s.patches)
    for (const Vec3& c : p.control) top = std::max(top, c.z);
  EXPECT_EQ(lifted.passes.size(), input.passes.size()) << label;
  for (std::size_t i = 0; i < lifted.passes.size(); i += passStride) {
    const ToolPass& pass = lifted.passes[i];
    const ToolPass& original = input.passes[i];
    const std::string where = label + " pass " + std::to_string(i);
    EXPECT_EQ(pass.start.x, original.start.x) << where;
    EXPECT_EQ(pass.start.y, original.start.y) << where;
    EXPECT_GE(pass.start.z, original.start.z) << where;
    Vec3 at = pass.start;
    for (std::size_t m = 0; m < pass.moves.size(); ++m) {
      const std::vector<Vec3> points = pointsOn(at, pass.moves[m], 1);
      for (std::size_t k = 1; k < points.size(); ++k) {
        const double depth = R - referenceDistance(s, points[k]);
        out.deepest = std::max(out.deepest, depth);
        ++out.samples;
        EXPECT_LE(depth, eps + 1e-12) << where << " move " << m;
      }
      at = pass.moves[m].end;
      if (m % 16 == 0) {  // the shank: clear straight up
        for (double f : {0.1, 0.4, 1.0}) {
          const Vec3 up{at.x, at.y, at.z + f * std::max(0.0, top + R - at.z)};
          EXPECT_GE(referenceDistance(s, up), R - eps - 1e-12) << where << " above move " << m;
        }
      }
    }
    // The input vertices: same (x, y), not lower, touching.
    EXPECT_EQ(moveMap[i].size(), original.moves.size()) << where;
    if (moveMap[i].size() != original.moves.size()) return out;
    for (std::size_t m = 0; m < original.moves.size(); ++m) {
      const Vec3 in = original.moves[m].end;
      const Vec3 outVertex = pass.moves[moveMap[i][m] - 1].end;
      EXPECT_EQ(outVertex.x, in.x) << where << " vertex " << m;
      EXPECT_EQ(outVertex.y, in.y) << where << " vertex " << m;
      EXPECT_GE(outVertex.z, in.z) << where << " vertex " << m;
      if (!cutting(i, m)) continue;
      const double loose = referenceDistance(s, outVertex) - R;
      out.loosestVertex = std::max(out.loosestVertex, loose);
      EXPECT_LE(loose, eps + slack + 1e-9) << where << " vertex " << m << " is not touching";
    }
  }
  return out;
}

// The paper's surfaces, contour (on N*) and raster (best feed), balls of 0.05, 0.25 and
// 1 in, coarse spacings (the envelope's correctness does not depend on them; every fourth
// pass judged): no sample deeper than eps, every input vertex touching.
TEST(DropEnvelope, PaperSurfacesBothStrategiesSeveralRadii) {
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = exampleSurface(name);
    const SurfaceDistance distance(s);
    const OptimalSlicing orientation = optimalSlicing(s);
    for (const double R : {0.05, 0.25, 1.0}) {
      for (const bool raster : {false, true}) {
        const std::string label = std::string(name) + (raster ? " raster" : " contour") + " R " + std::to_string(R);
        SCOPED_TRACE(label);
        ToolPath input;
        double slack = 0.0;
        std::vector<RasterPass> passes;
        if (raster) {
          RasterOptions o;
          o.bestAngle = true;
          o.toolRadius = R;
          o.spacing = 0.3;
          o.dropEnvelope = false;
          RasterPaths paths = rasterPaths(s, o);
          input = std::move(paths.path);
          passes = std::move(paths.passes);
          slack = 1e-4 * surfaceScale(s);  // polygonised arcs' vertices: the arc tolerance
        } else {
          ContourOptions o;
          o.normal = orientation.normal.z < 0.0 ? -orientation.normal : orientation.normal;
          o.toolRadius = R;
          o.spacing = 0.3;
          o.dropEnvelope = false;
          input = contourPaths(s, o).path;
        }
        EnvelopeReport report;
        std::vector<std::vector<std::size_t>> moveMap;
        const ToolPath lifted = liftToDropEnvelope(distance, input, {}, report, &moveMap);
        EXPECT_EQ(report.unprovenMoves, 0u);
        const double eps = report.depthTolerance;
        EXPECT_DOUBLE_EQ(eps, 1e-6 * surfaceScale(s));
        // The raster's cutting vertices: after the link and the entry, before the exit.
        const auto cutting = [&](std::size_t pass, std::size_t move) {
          if (!raster) return true;
          const RasterPass& info = passes[pass];
          return move >= info.linkMoves + info.entryMoves &&
                 move + info.exitMoves < input.passes[pass].moves.size();
        };
        const Judged judged = judge(s, input, lifted, moveMap, eps, slack, 4, label, cutting);
        // Independently of the proofs, the sampled gouge check agrees.
        const GougeReport gouge = gougeCheck(distance, lifted, R / 50.0);
        EXPECT_LE(gouge.signedMaxDepth, eps + 1e-12);
        std::printf("[          ] %s: %zu -> %zu moves, %zu vertices lifted (max %.6f), %zu "
                    "stretches; %zu samples, deepest %.3g (eps %.3g), loosest vertex %.3g\n",
                    label.c_str(), report.movesIn, report.movesOut, report.verticesLifted,
                    report.maxLift, report.stretches.size(), judged.samples, judged.deepest, eps,
                    judged.loosestVertex);
      }
    }
  }
}

// The issue's acceptance: the paper's surfaces, both strategies, balls from 0.05 to 1 in, cut
// by the simulator (cut_simulation.hpp: exact ball bottoms at every grid point, independent
// of how the paths were made): no gouge beyond what the drop envelope's eps allows, measured
// vertically. A ball reaching eps into the surface cuts a vertical gouge of at most
// sqrt(2 R eps - eps^2) (touching at its equator, as beside the surface's boundary, where
// both strategies' passes now run on: the measured worst are 1e-5 to 9e-5 in, there), and of
// eps / n_z where it touches from above on a slope.
TEST(DropEnvelope, SimulatedCutFindsNoGouge) {
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = exampleSurface(name);
    const OptimalSlicing orientation = optimalSlicing(s);
    for (const double R : {0.05, 0.25, 1.0}) {
      for (const bool raster : {false, true}) {
        const std::string label = std::string(name) + (raster ? " raster" : " contour") + " R " + std::to_string(R);
        SCOPED_TRACE(label);
        ToolPath path;
        double eps = 0.0;
        if (raster) {
          RasterOptions o;
          o.bestAngle = true;
          o.toolRadius = R;
          o.spacing = 0.15;
          RasterPaths paths = rasterPaths(s, o);
          path = std::move(paths.path);
          eps = paths.envelope.depthTolerance;
        } else {
          ContourOptions o;
          o.normal = orientation.normal.z < 0.0 ? -orientation.normal : orientation.normal;
          o.toolRadius = R;
          o.spacing = 0.15;
          ContourPaths paths = contourPaths(s, o);
          path = std::move(paths.path);
          eps = paths.envelope.depthTolerance;
        }
        SimulationOptions options;
        options.toolRadius = R;
        options.scallopHeight = std::min(0.01, 0.1 * R);
        options.resolution = 0.01;
        const SimulationReport report = verifyToolPath(s, path, options);
        EXPECT_LE(report.maxGouge, std::sqrt(2.0 * R * eps - eps * eps));
        std::printf("[          ] %s: simulated deepest gouge %.3g (eps %.3g), %zu points\n", label.c_str(),
                    report.maxGouge, eps, report.design.z.size());
      }
    }
  }
}

// Random creased surfaces (two patches meeting at an angle along x = 3) under contour paths
// along random plane normals and balls up to 1.5 (concave creases the ball cannot enter):
// every pass judged.
TEST(DropEnvelope, CreasedSurfacesContour) {
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), radius(0.1, 1.5);
  std::size_t lifted = 0;
  for (int trial = 0; trial < 8; ++trial) {
    const Surface s = creasedSurface(rng);
    const double R = radius(rng);
    ContourOptions o;
    o.normal = normalized(Vec3{unit(rng), unit(rng), 0.3 * unit(rng)});
    o.toolRadius = R;
    o.spacing = 0.4;
    o.dropEnvelope = false;
    ToolPath input;
    try {
      input = contourPaths(s, o).path;
    } catch (const Error&) {
      continue;  // a random net that folds: not a regular surface
    }
    const std::string label = "trial " + std::to_string(trial) + " R " + std::to_string(R);
    SCOPED_TRACE(label);
    EnvelopeReport report;
    std::vector<std::vector<std::size_t>> moveMap;
    const ToolPath out = liftToDropEnvelope(SurfaceDistance(s), input, {}, report, &moveMap);
    EXPECT_EQ(report.unprovenMoves, 0u);
    judge(s, input, out, moveMap, report.depthTolerance, 0.0, 2, label,
          [](std::size_t, std::size_t) { return true; });
    lifted += report.verticesLifted;
  }
  EXPECT_GT(lifted, 0u);
}

// Surfaces that are not graphs over the raster direction (an S-fold whose sections turn
// back, a closed section, the teapot's lid with its knob), cut with the drop envelope on:
// the planes where it is not a graph follow what a ball from above sees, and every sampled
// centre, and the shank above every vertex, keeps R - eps from the surface.
TEST(DropEnvelope, RasterOnSurfacesThatAreNotGraphs) {
  BezierPatch fold;
  const double xs[4] = {0.0, 4.0, -2.0, 2.0};
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) fold.control.push_back({xs[k], double(j), double(k)});
  BezierPatch loop;
  const Vec2 xz[4] = {{0.0, 0.0}, {3.0, 3.0}, {-3.0, 3.0}, {0.0, 0.0}};
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) loop.control.push_back({xz[k].x, double(j), xz[k].y});
  const Surface lid = exampleSurface("teapot-lid");
  struct Case {
    std::string name;
    Surface surface;
    double angleDeg;
  };
  for (const Case& c : {Case{"S-fold", Surface{Units::inch, {fold}}, 0.0},
                        Case{"closed section", Surface{Units::inch, {loop}}, 0.0},
                        Case{"teapot lid", lid, 30.0}}) {
    SCOPED_TRACE(c.name);
    RasterOptions o;
    o.angleRad = c.angleDeg * std::numbers::pi / 180.0;
    o.toolRadius = 0.25;
    o.spacing = 0.35;
    o.dropEnvelope = false;
    EXPECT_THROW(rasterPaths(c.surface, o), Error);  // in-plane alone: refused, named
    o.dropEnvelope = true;
    const RasterPaths r = rasterPaths(c.surface, o);
    EXPECT_GT(r.visibleFromAbovePlanes, 0u);
    EXPECT_EQ(r.envelope.unprovenMoves, 0u);
    const double eps = r.envelope.depthTolerance;
    // The lifted path against the reference (no input to compare with: tightness is the
    // paper surfaces' test); the map is the identity on the lifted path itself.
    std::vector<std::vector<std::size_t>> identity;
    for (const ToolPass& pass : r.path.passes) {
      identity.emplace_back();
      for (std::size_t m = 0; m < pass.moves.size(); ++m) identity.back().push_back(m + 1);
    }
    const Judged judged = judge(c.surface, r.path, r.path, identity, eps, 0.0, 4, c.name,
                                [](std::size_t, std::size_t) { return false; });
    EXPECT_GT(judged.samples, 100u);
    const GougeReport gouge = gougeCheck(c.surface, r.path, 0.25 / 50.0);
    EXPECT_LE(gouge.signedMaxDepth, eps + 1e-12);
    std::printf("[          ] %s: %zu planes (%zu not a graph), %zu moves; deepest %.3g (eps %.3g)\n",
                c.name.c_str(), r.stats.planes, r.visibleFromAbovePlanes, r.envelope.movesOut,
                judged.deepest, eps);
  }
}

// The passes are lifted in parallel: the result is the same, bit for bit, for 1, 2 and 5
// threads (raster: its linked passes start exactly where the previous one was lifted to).
TEST(DropEnvelope, SameResultForAnyNumberOfThreads) {
  const Surface s = exampleSurface("paper-2");
  RasterOptions o;
  o.bestAngle = true;
  o.toolRadius = 0.25;
  o.spacing = 0.2;
  o.dropEnvelope = false;
  const ToolPath input = rasterPaths(s, o).path;
  const SurfaceDistance distance(s);
  std::vector<ToolPath> outs;
  for (const std::size_t threads : {1u, 2u, 5u}) {
    EnvelopeOptions options;
    options.threads = threads;
    EnvelopeReport report;
    outs.push_back(liftToDropEnvelope(distance, input, options, report));
  }
  for (std::size_t k = 1; k < outs.size(); ++k) {
    ASSERT_EQ(outs[k].passes.size(), outs[0].passes.size());
    for (std::size_t p = 0; p < outs[0].passes.size(); ++p) {
      const ToolPass& a = outs[0].passes[p];
      const ToolPass& b = outs[k].passes[p];
      EXPECT_EQ(a.start, b.start) << p;
      ASSERT_EQ(a.moves.size(), b.moves.size()) << p;
      for (std::size_t m = 0; m < a.moves.size(); ++m) EXPECT_EQ(a.moves[m].end, b.moves[m].end) << p << " " << m;
    }
  }
  // Continuity of the linked passes.
  for (std::size_t p = 1; p < outs[0].passes.size(); ++p) {
    if (!input.passes[p].retractBefore) {
      EXPECT_EQ(outs[0].passes[p].start, outs[0].passes[p - 1].moves.back().end) << p;
    }
  }
}

// The options and the path are checked.
TEST(DropEnvelope, RejectsBadInput) {
  const Surface s = exampleSurface("paper-1");
  const SurfaceDistance distance(s);
  ToolPath path;
  path.toolRadius = 0.25;
  path.passes.push_back({{1, 1, 2}, {{MoveKind::line, {2, 2, 2}, {}, ArcPlane::xy, true}}, true});
  EnvelopeReport report;
  EnvelopeOptions bad;
  bad.depthTolerance = -1.0;
  EXPECT_THROW(liftToDropEnvelope(distance, path, bad, report), Error);
  bad.depthTolerance = 1.0;  // not below R
  EXPECT_THROW(liftToDropEnvelope(distance, path, bad, report), Error);
  ToolPath mm = path;
  mm.units = Units::millimetre;
  EXPECT_THROW(liftToDropEnvelope(distance, mm, {}, report), Error);
  ToolPath nan = path;
  nan.passes[0].moves[0].end.z = std::nan("");
  EXPECT_THROW(liftToDropEnvelope(distance, nan, {}, report), Error);
  EnvelopeOptions tiny;
  tiny.maxMoves = 1;
  ToolPath two = path;
  two.passes[0].moves.push_back({MoveKind::line, {2.5, 2, 2}, {}, ArcPlane::xy, true});
  EXPECT_THROW(liftToDropEnvelope(distance, two, tiny, report), Error);
  // Far above the surface nothing moves.
  EXPECT_NO_THROW({
    const ToolPath same = liftToDropEnvelope(distance, path, {}, report);
    EXPECT_EQ(same.passes[0].start, path.passes[0].start);
    EXPECT_EQ(same.passes[0].moves.back().end, path.passes[0].moves.back().end);
  });
}


// ---------------------------------------------------------------------------------------
// Drop-cutter heights, run-ons and drop lines against a brute-force reference
// ---------------------------------------------------------------------------------------

constexpr double kInf = std::numeric_limits<double>::infinity();

// A compass (pattern) search for a maximum of f on [0, 1]^2 from (u, v): the eight
// neighbours at step h, move to the best if it improves, else halve h (the same scheme as
// distance_reference.hpp's, for any function: no derivatives, nothing shared with the
// Newton solves under test). Returns the value; (u, v) end at the maximiser found.
template <typename F>
double compassMaximum(const F& f, double& u, double& v, double h) {
  double best = f(u, v);
  while (h > 1e-12) {
    double bestU = u, bestV = v;
    for (int du = -1; du <= 1; ++du) {
      for (int dv = -1; dv <= 1; ++dv) {
        if (du == 0 && dv == 0) continue;
        const double tu = std::clamp(u + du * h, 0.0, 1.0);
        const double tv = std::clamp(v + dv * h, 0.0, 1.0);
        const double value = f(tu, tv);
        if (value > best) best = value, bestU = tu, bestV = tv;
      }
    }
    if (bestU == u && bestV == v) {
      h *= 0.5;
    } else {
      u = bestU, v = bestV;
    }
  }
  return best;
}

// A surface point found by a reference search: the patch and parameters, and its value.
struct Found {
  double value = -kInf;
  std::size_t patch = 0;
  double u = 0.0, v = 0.0;
};

// The surface sampled on a (grid + 1)^2 grid per patch, bucketed by xy in square cells, as
// the brute-force judge of the drop envelope
//     Z(x, y) = max { p_z + sqrt(R^2 - d^2) : p on the surface, d = |p_xy - (x, y)| <= R }.
// Every sample is a surface point, so the grid's maximum (gridDrop) and any refinement of it
// (refinedDrop: compass searches from the best samples) are lower bounds of Z, the refined
// one converging to Z when a start lies in the maximiser's basin (a 300 x 300 grid puts
// several in each). gridUpper is a proven upper bound from the grid spacing (see there).
class DropReference {
 public:
  DropReference(const Surface& s, int grid) : surface_(s), grid_(grid) {
    lo_ = {kInf, kInf, 0.0};
    Vec3 hi{-kInf, -kInf, 0.0};
    for (std::size_t p = 0; p < s.patches.size(); ++p) {
      const BezierPatch& patch = s.patches[p];
      // The covering radius: every point r(u, v) of a cell lies within (h / 2)(|r_u| + |r_v|)
      // of the cell's nearest corner sample (mean value theorem along u, then along v; h =
      // 1 / grid), and |r_u| <= m max |p_{j+1,k} - p_jk| over the patch (the hodograph's
      // control net bounds it: convex hull property); likewise |r_v|.
      double su = 0.0, sv = 0.0;
      for (int j = 0; j <= patch.degreeU; ++j)
        for (int k = 0; k <= patch.degreeV; ++k) {
          if (j < patch.degreeU) su = std::max(su, norm(patch.at(j + 1, k) - patch.at(j, k)));
          if (k < patch.degreeV) sv = std::max(sv, norm(patch.at(j, k + 1) - patch.at(j, k)));
        }
      delta_ = std::max(delta_, 0.5 / grid * (patch.degreeU * su + patch.degreeV * sv));
      for (int i = 0; i <= grid; ++i)
        for (int j = 0; j <= grid; ++j) {
          const double u = double(i) / grid, v = double(j) / grid;
          const Vec3 q = point(patch, u, v);
          samples_.push_back({q, p, u, v});
          lo_ = {std::min(lo_.x, q.x), std::min(lo_.y, q.y), 0.0};
          hi = {std::max(hi.x, q.x), std::max(hi.y, q.y), 0.0};
        }
    }
    cell_ = std::max(hi.x - lo_.x, hi.y - lo_.y) / 64.0;
    columns_ = static_cast<long>((hi.x - lo_.x) / cell_) + 1;
    rows_ = static_cast<long>((hi.y - lo_.y) / cell_) + 1;
    buckets_.assign(static_cast<std::size_t>(columns_ * rows_), {});
    for (std::size_t k = 0; k < samples_.size(); ++k) buckets_[bucket(samples_[k].p.x, samples_[k].p.y)].push_back(k);
  }

  double delta() const { return delta_; }

  // Every sample within horizontal distance r of (x, y), as f(sample, d).
  template <typename F>
  void near(double x, double y, double r, const F& f) const {
    const long i0 = std::max(0L, static_cast<long>(std::floor((x - r - lo_.x) / cell_)));
    const long i1 = std::min(columns_ - 1, static_cast<long>(std::floor((x + r - lo_.x) / cell_)));
    const long j0 = std::max(0L, static_cast<long>(std::floor((y - r - lo_.y) / cell_)));
    const long j1 = std::min(rows_ - 1, static_cast<long>(std::floor((y + r - lo_.y) / cell_)));
    for (long j = j0; j <= j1; ++j)
      for (long i = i0; i <= i1; ++i)
        for (const std::size_t k : buckets_[static_cast<std::size_t>(j * columns_ + i)]) {
          const Sample& s = samples_[k];
          const double d = std::hypot(s.p.x - x, s.p.y - y);
          if (d <= r) f(s, d);
        }
  }

  // max over samples within R of z + sqrt(R^2 - d^2); -infinity when none.
  double gridDrop(double x, double y, double R) const {
    double best = -kInf;
    near(x, y, R, [&](const Sample& s, double d) { best = std::max(best, s.p.z + std::sqrt(R * R - d * d)); });
    return best;
  }

  // A proven upper bound of Z from the grid: every surface point p with d(p) <= R lies
  // within delta of a sample s (the covering radius above), so d_s <= R + delta, p_z <= s_z +
  // delta and d(p) >= d_s - delta, and p_z + sqrt(R^2 - d(p)^2) <= s_z + delta +
  // sqrt(R^2 - max(0, d_s - delta)^2). The maximum of that over the samples within R + delta
  // bounds Z; it exceeds the grid's own maximum by at most delta + sqrt(2 R delta + delta^2)
  // (sqrt(a) - sqrt(b) <= sqrt(a - b)), the square root only where the contact is near the
  // ball's equator. -infinity when no sample lies within R + delta: no surface point within R.
  double gridUpper(double x, double y, double R) const {
    double best = -kInf;
    near(x, y, R + delta_, [&](const Sample& s, double d) {
      const double inner = std::max(0.0, d - delta_);
      best = std::max(best, s.p.z + delta_ + std::sqrt(std::max(0.0, R * R - inner * inner)));
    });
    return best;
  }

  // The grid's maximum refined by compass searches from the best samples of each patch:
  // still a surface point's contact height, so still a lower bound of Z.
  Found refinedDrop(double x, double y, double R) const {
    const auto value = [&](std::size_t patch, double u, double v) {
      const Vec3 q = point(surface_.patches[patch], u, v);
      const double d2 = (q.x - x) * (q.x - x) + (q.y - y) * (q.y - y);
      return d2 < R * R ? q.z + std::sqrt(R * R - d2) : -kInf;
    };
    return refine(x, y, R, value, [&](const Sample& s, double d) { return s.p.z + std::sqrt(R * R - d * d); });
  }

  // The least horizontal distance from (x, y) to the surface (as a maximum of -d), refined:
  // an upper bound of the true least distance, converging to it.
  Found refinedHorizontal(double x, double y, double reach) const {
    const auto value = [&](std::size_t patch, double u, double v) {
      const Vec3 q = point(surface_.patches[patch], u, v);
      return -std::hypot(q.x - x, q.y - y);
    };
    Found f = refine(x, y, reach, value, [](const Sample&, double d) { return -d; });
    f.value = -f.value;  // +infinity when nothing lies within reach
    return f;
  }

 private:
  struct Sample {
    Vec3 p;
    std::size_t patch;
    double u, v;
  };
  std::size_t bucket(double x, double y) const {
    const long i = std::clamp(static_cast<long>(std::floor((x - lo_.x) / cell_)), 0L, columns_ - 1);
    const long j = std::clamp(static_cast<long>(std::floor((y - lo_.y) / cell_)), 0L, rows_ - 1);
    return static_cast<std::size_t>(j * columns_ + i);
  }
  // The best three samples of each patch within `reach` (by sampleValue), each refined by a
  // compass search on value; the best result.
  template <typename V, typename S>
  Found refine(double x, double y, double reach, const V& value, const S& sampleValue) const {
    std::vector<std::vector<std::pair<double, const Sample*>>> best(surface_.patches.size());
    near(x, y, reach, [&](const Sample& s, double d) { best[s.patch].push_back({sampleValue(s, d), &s}); });
    Found out;
    for (auto& list : best) {
      const std::size_t keep = std::min<std::size_t>(3, list.size());
      std::partial_sort(list.begin(), list.begin() + static_cast<std::ptrdiff_t>(keep), list.end(),
                        [](const auto& a, const auto& b) { return a.first > b.first; });
      for (std::size_t k = 0; k < keep; ++k) {
        const Sample& s = *list[k].second;
        double u = s.u, v = s.v;
        const double found = compassMaximum([&](double a, double b) { return value(s.patch, a, b); }, u, v,
                                            1.0 / grid_);
        if (found > out.value) out = {found, s.patch, u, v};
      }
    }
    return out;
  }

  const Surface& surface_;
  int grid_;
  double delta_ = 0.0;
  std::vector<Sample> samples_;
  Vec3 lo_;
  double cell_ = 1.0;
  long columns_ = 1, rows_ = 1;
  std::vector<std::vector<std::size_t>> buckets_;
};

// The reference closest point to p: a (grid + 1)^2 grid per patch, the best starts refined
// by compass searches (as distance_reference.hpp, keeping the parameters).
Found referenceClosest(const Surface& s, Vec3 p, int grid = 24) {
  Found out;
  for (std::size_t patchIndex = 0; patchIndex < s.patches.size(); ++patchIndex) {
    const BezierPatch& patch = s.patches[patchIndex];
    std::vector<std::pair<double, std::pair<double, double>>> samples;
    for (int i = 0; i <= grid; ++i)
      for (int j = 0; j <= grid; ++j) {
        const double u = double(i) / grid, v = double(j) / grid;
        samples.push_back({-norm(point(patch, u, v) - p), {u, v}});
      }
    std::partial_sort(samples.begin(), samples.begin() + 4, samples.end(),
                      [](const auto& a, const auto& b) { return a.first > b.first; });
    for (int k = 0; k < 4; ++k) {
      double u = samples[k].second.first, v = samples[k].second.second;
      const double found = compassMaximum([&](double a, double b) { return -norm(point(patch, a, b) - p); }, u, v,
                                          1.0 / grid);
      if (found > out.value) out = {found, patchIndex, u, v};
    }
  }
  out.value = -out.value;
  return out;
}

// Random surfaces for the drop cutter: creased pairs (creasedSurface) and single bicubic
// graphs with a deep, narrow valley (concave radii far below the larger balls).
Surface valleySurface(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> z(-0.3, 0.3);
  BezierPatch p;
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) p.control.push_back({double(k), double(j), (k == 1 || k == 2 ? -1.2 : 0.4) + z(rng)});
  return Surface{Units::inch, {p}};
}

// DropCutter::height against the reference at random points over and around the surface
// (a margin of R + 0.3 beyond its xy box), balls of 0.05, 0.25 and 1 in. With eps the depth
// tolerance, the contract gives, per point:
//   - finite Z: the vertical segment from Z up is R - eps / 2 clear, so every surface point
//     within R - eps / 2 horizontally stands at least sqrt((R - eps / 2)^2 - d^2) below Z:
//     Z >= the reference's refined drop height for the radius R - eps / 2 (a genuine
//     contact height), and the ball at Z is R - eps / 2 from the whole surface (the distance
//     reference, which never understates a distance, over the ball's centre);
//   - Z is the lowest proven height within eps / 4 and the true Z is proven at its own
//     height with eps / 2 to spare, so Z <= Z_true + eps / 4, with Z_true <= gridUpper (a
//     proven bound) and Z_true ~ the refined drop height (a lower bound; equal when the
//     search found the maximiser: checked to 1e-9);
//   - -infinity exactly where no surface point lies within R of the vertical line, up to the
//     proof's slack: never where a surface point lies within R - eps / 2 (the reference's
//     least horizontal distance is attained by a surface point), always where none lies
//     within R (within 1e-9 of the search's refinement).
TEST(DropCutter, HeightsAgainstABruteForceDropOnPaperAndRandomSurfaces) {
  std::mt19937_64 rng(4242);
  struct Case {
    std::string name;
    Surface surface;
  };
  std::vector<Case> cases = {{"paper-1", exampleSurface("paper-1")}, {"paper-2", exampleSurface("paper-2")}};
  for (int k = 0; k < 2; ++k) cases.push_back({"creased " + std::to_string(k), creasedSurface(rng)});
  cases.push_back({"valley", valleySurface(rng)});
  std::size_t finite = 0, infinite = 0, bisected = 0;
  for (const Case& c : cases) {
    const Surface& s = c.surface;
    const SurfaceDistance distance(s);
    const DropReference reference(s, 300);
    const double scale = surfaceScale(s);
    const double eps = 1e-6 * scale;
    Vec3 lo{kInf, kInf, 0}, hi{-kInf, -kInf, 0};
    for (const BezierPatch& p : s.patches)
      for (const Vec3& q : p.control) lo = {std::min(lo.x, q.x), std::min(lo.y, q.y), 0}, hi = {std::max(hi.x, q.x), std::max(hi.y, q.y), 0};
    double worstAbove = -kInf, worstBelow = -kInf, worstUpperGap = 0.0;
    for (const double R : {0.05, 0.25, 1.0}) {
      DropCutter cutter(distance, R);
      std::uniform_real_distribution<double> x(lo.x - R - 0.3, hi.x + R + 0.3), y(lo.y - R - 0.3, hi.y + R + 0.3);
      for (int trial = 0; trial < 200; ++trial) {
        const double px = x(rng), py = y(rng);
        const double z = cutter.height(px, py);
        const std::string where = c.name + " R " + std::to_string(R) + " at (" + std::to_string(px) + ", " +
                                  std::to_string(py) + ")";
        if (z == -kInf) {
          ++infinite;
          const Found nearest = reference.refinedHorizontal(px, py, R + 0.1);
          EXPECT_GE(nearest.value, R - 0.5 * eps - 1e-12) << where << ": a surface point within R - eps / 2";
          EXPECT_EQ(reference.gridDrop(px, py, R - 0.5 * eps), -kInf) << where;
          continue;
        }
        ++finite;
        ASSERT_TRUE(std::isfinite(z)) << where << ": " << z;
        // A sample within R settles "something within R"; otherwise the refined search.
        if (reference.gridDrop(px, py, R) == -kInf) {
          EXPECT_LE(reference.refinedHorizontal(px, py, R + 0.1).value, R + 1e-9) << where << ": nothing within R";
        }
        const Found refined = reference.refinedDrop(px, py, R);
        // Below: never below a contact of the ball of radius R - eps / 2: the grid's, and the
        // refined maximiser's for R (any surface point gives a lower bound).
        const Vec3 contact = point(s.patches[refined.patch], refined.u, refined.v);
        const double d = std::hypot(contact.x - px, contact.y - py), shrunk = R - 0.5 * eps;
        const double lower = d < shrunk ? contact.z + std::sqrt(shrunk * shrunk - d * d) : -kInf;
        EXPECT_GE(z, std::max(lower, reference.gridDrop(px, py, shrunk)) - 1e-12 * scale) << where;
        EXPECT_GE(referenceDistance(s, {px, py, z}), R - 0.5 * eps - 1e-12 * scale) << where;
        // Above: at most eps / 4 over the true height, which the grid bounds (proven) and the
        // refined search attains.
        const double upper = reference.gridUpper(px, py, R);
        EXPECT_LE(z, upper + 0.25 * eps + 1e-12 * scale) << where;
        EXPECT_LE(z, refined.value + 0.25 * eps + 1e-9 * scale) << where;
        worstAbove = std::max(worstAbove, z - refined.value);
        worstBelow = std::max(worstBelow, refined.value - z);
        worstUpperGap = std::max(worstUpperGap, upper - refined.value);
        if (z - refined.value > 1e-12 * scale) ++bisected;  // above a contact: the bisection's answer
      }
    }
    std::printf("[          ] %s: drop height - refined reference in [%.3g, %.3g] (eps %.3g); grid bound "
                "within %.3g (delta %.3g)\n",
                c.name.c_str(), -worstBelow, worstAbove, eps, worstUpperGap, reference.delta());
  }
  std::printf("[          ] %zu finite heights (%zu above a found contact), %zu -infinity\n", finite, bisected, infinite);
  EXPECT_GT(finite, 2000u);
  EXPECT_GT(infinite, 300u);
}


// Closed forms on a horizontal square z = 0.5 over [0, 2]^2: R above it over the square, the
// ball's rim on the edge beyond it (z0 + sqrt(R^2 - d^2) at distance d), -infinity beyond R
// (also a hair beyond, 1e-7 < eps / 2, where nothing lies within R), finite a hair more than
// eps / 2 inside; and the errors.
TEST(DropCutter, ClosedFormsOnAPlaneAndBadInput) {
  BezierPatch square{1, 1, {{0, 0, 0.5}, {0, 2, 0.5}, {2, 0, 0.5}, {2, 2, 0.5}}};
  const Surface s{Units::inch, {square}};
  const SurfaceDistance distance(s);
  const double R = 0.25, eps = 1e-6 * surfaceScale(s);
  DropCutter cutter(distance, R);
  for (const Vec2 p : {Vec2{1.0, 1.0}, Vec2{0.0, 0.0}, Vec2{2.0, 0.7}, Vec2{1e-9, 1.9}})
    EXPECT_NEAR(cutter.height(p.x, p.y), 0.5 + R, 0.25 * eps + 1e-12) << p.x << ", " << p.y;
  for (const double d : {0.01, 0.1, 0.2, 0.249, R - 1e-5}) {
    const double want = 0.5 + std::sqrt(R * R - d * d);
    // Within eps / 4 above the contact; below it no further than where the clearance
    // R - eps / 2 is reached: z0 + sqrt((R - eps / 2)^2 - d^2).
    const double shrunk = R - 0.5 * eps;
    const double low = d < shrunk ? 0.5 + std::sqrt(shrunk * shrunk - d * d) : -kInf;
    for (const Vec2 p : {Vec2{2.0 + d, 1.0}, Vec2{1.0, -d}, Vec2{-d * std::sqrt(0.5), -d * std::sqrt(0.5)}}) {
      const double z = cutter.height(p.x, p.y);
      EXPECT_LE(z, want + 0.25 * eps + 1e-12) << d;
      EXPECT_GE(z, low - 1e-12) << d;
    }
  }
  EXPECT_EQ(cutter.height(2.0 + R + 1e-7, 1.0), -kInf);
  EXPECT_EQ(cutter.height(1.0, 2.0 + R + 0.3), -kInf);
  EXPECT_EQ(cutter.height(-100.0, 1e6), -kInf);
  EXPECT_TRUE(std::isfinite(cutter.height(2.0 + R - eps, 1.0)));
  // Bad input.
  EXPECT_THROW(cutter.height(std::nan(""), 1.0), Error);
  EXPECT_THROW(cutter.height(1.0, kInf), Error);
  EXPECT_THROW(DropCutter(distance, 0.0), Error);
  EXPECT_THROW(DropCutter(distance, -0.25), Error);
  EXPECT_THROW(DropCutter(distance, std::nan("")), Error);
  EXPECT_THROW(DropCutter(distance, kInf), Error);
  EnvelopeOptions coarse;
  coarse.depthTolerance = R;  // eps must lie below R
  EXPECT_THROW(DropCutter(distance, R, coarse), Error);
}


// ---- run-ons and drop lines ----

enum class Tri { no, maybe, yes };

// The contract's verdicts on a centre over (x, y) dropped onto the envelope, judged by the
// reference, with the proofs' slack as "maybe":
//   - clear (nothing within R of the vertical line, the run stops): no where a surface point
//     lies within R - eps / 2 (the proof at R - eps / 2 cannot pass), yes where none lies
//     within R (the refined least horizontal distance beyond R + 1e-9), maybe between;
//   - inside the band: W(q) = normal . (q + offset n(q)) of the closest surface point q (the
//     reference's), maybe within tauW of lo or hi: a point whose distance is within the
//     distance's tolerance t of the least lies within about sqrt(2 R t) of the foot (the
//     distance grows by s^2 / (2 R) at s from it on a plane, more slowly only on concave
//     radii near R), and W moves by at most that times (1 + R |kappa|) <= 2 there.
class BandJudge {
 public:
  BandJudge(const Surface& s, const DropReference& reference, const RunOnBand& band, double R, double eps,
            double distanceTolerance)
      : s_(s), reference_(reference), band_(band), R_(R), eps_(eps),
        tauW_(2.0 * std::sqrt(2.0 * R * distanceTolerance)) {}

  Tri clear(double x, double y) const {
    if (reference_.gridDrop(x, y, R_ - 0.5 * eps_) > -kInf) return Tri::no;
    const double d = reference_.refinedHorizontal(x, y, R_ + 0.1).value;
    if (d < R_ - 0.5 * eps_) return Tri::no;
    return d > R_ + 1e-9 ? Tri::yes : Tri::maybe;
  }

  double w(Vec3 c) const {
    const Found q = referenceClosest(s_, c);
    const Vec3 foot = point(s_.patches[q.patch], q.u, q.v);
    return dot(band_.normal, foot + band_.offset * upwardNormal(s_, q.patch, q.u, q.v));
  }

  Tri inside(Vec3 c) const {
    const double value = w(c);
    if (value < band_.lo - tauW_ || value > band_.hi + tauW_) return Tri::no;
    return value >= band_.lo + tauW_ && value <= band_.hi - tauW_ ? Tri::yes : Tri::maybe;
  }

  // The reference's height over (x, y) (the refined drop: the true one, see the DropCutter test).
  double height(double x, double y) const { return reference_.refinedDrop(x, y, R_).value; }

  // A dropped centre stands on the envelope as DropCutter's heights do (see there).
  void expectOnEnvelope(Vec3 c, const std::string& where) const {
    const double scale = surfaceScale(s_);
    const Found refined = reference_.refinedDrop(c.x, c.y, R_);
    EXPECT_LE(c.z, refined.value + 0.25 * eps_ + 1e-9 * scale) << where;
    const Vec3 contact = point(s_.patches[refined.patch], refined.u, refined.v);
    const double d = std::hypot(contact.x - c.x, contact.y - c.y), shrunk = R_ - 0.5 * eps_;
    const double lower = d < shrunk ? contact.z + std::sqrt(shrunk * shrunk - d * d) : -kInf;
    EXPECT_GE(c.z, std::max(lower, reference_.gridDrop(c.x, c.y, shrunk)) - 1e-12 * scale) << where;
  }

  double tauW() const { return tauW_; }

 private:
  const Surface& s_;
  const DropReference& reference_;
  RunOnBand band_;
  double R_, eps_, tauW_;
};

// The numbers of vertices runOnPastEnd may return for candidate vertices k = 1 .. steps, the
// contract's rule with every "maybe" taken both ways: the run stops before the first vertex
// judged clear, then is cut back to its last vertex inside the band. `clear(k)` and
// `inside(k)` are evaluated lazily, in order, only as far as a stop is certain.
template <typename Clear, typename Inside>
std::vector<std::size_t> allowedRunOnCounts(std::size_t steps, const Clear& clear, const Inside& inside) {
  std::vector<std::size_t> allowed;
  std::vector<Tri> in(1, Tri::no);  // in[k], k >= 1
  const auto stopBefore = [&](std::size_t stop) {
    std::size_t last = 0;
    for (std::size_t k = 1; k < stop; ++k)
      if (in[k] == Tri::yes) last = k;
    allowed.push_back(last);
    for (std::size_t k = last + 1; k < stop; ++k)
      if (in[k] == Tri::maybe) allowed.push_back(k);
  };
  bool certain = false;
  for (std::size_t k = 1; k <= steps && !certain; ++k) {
    const Tri c = clear(k);
    if (c != Tri::no) stopBefore(k);
    certain = c == Tri::yes;
    if (!certain) in.push_back(inside(k));
  }
  if (!certain) stopBefore(steps + 1);
  return allowed;
}

struct RunOnCase {
  Vec3 end, direction;
  RunOnBand band;
  double step = 0.0;
  std::string what;
};

struct RunOnJudged {
  std::size_t vertices = 0;
  bool ambiguous = false;  // the contract allowed more than one number
  bool cutBack = false;    // fewer than the vertices before the stop: the band's cut mattered
};

// One run-on against the reference: the vertices at end + k step h (k = 1, 2, ...) to
// rounding, on the envelope, at most length / step of them, their number one the contract
// allows, the last one touching inside the band.
RunOnJudged judgeRunOn(const Surface& s, const SurfaceDistance& distance, const DropReference& reference,
                       const RunOnCase& c, double R, double length) {
  const double eps = 1e-6 * surfaceScale(s);
  const std::vector<Vec3> run = runOnPastEnd(distance, c.end, c.direction, R, c.band, c.step, length);
  const BandJudge judge(s, reference, c.band, R, eps, distance.tolerance());
  const double horizontal = std::hypot(c.direction.x, c.direction.y);
  const Vec3 h{c.direction.x / horizontal, c.direction.y / horizontal, 0.0};
  const auto steps = static_cast<std::size_t>(std::floor(length / c.step));
  EXPECT_LE(run.size(), steps) << c.what;
  const auto at = [&](std::size_t k) { return c.end + (double(k) * c.step) * h; };
  for (std::size_t k = 1; k <= run.size(); ++k) {
    const Vec3 want = at(k);
    const std::string where = c.what + " vertex " + std::to_string(k);
    EXPECT_NEAR(run[k - 1].x, want.x, 1e-12 * surfaceScale(s)) << where;
    EXPECT_NEAR(run[k - 1].y, want.y, 1e-12 * surfaceScale(s)) << where;
    judge.expectOnEnvelope(run[k - 1], where);
  }
  const auto centre = [&](std::size_t k) {
    if (k <= run.size()) return run[k - 1];
    const Vec3 p = at(k);
    return Vec3{p.x, p.y, judge.height(p.x, p.y)};
  };
  const std::vector<std::size_t> allowed = allowedRunOnCounts(
      steps, [&](std::size_t k) { return judge.clear(at(k).x, at(k).y); },
      [&](std::size_t k) { return judge.inside(centre(k)); });
  EXPECT_NE(std::find(allowed.begin(), allowed.end(), run.size()), allowed.end())
      << c.what << ": " << run.size() << " vertices, the contract allows " << ::testing::PrintToString(allowed);
  if (!run.empty()) {
    EXPECT_NE(judge.inside(run.back()), Tri::no) << c.what << ": the last vertex is outside the band";
  }
  RunOnJudged out;
  out.vertices = run.size();
  out.ambiguous = allowed.size() > 1;
  std::size_t stop = 1;
  while (stop <= steps && judge.clear(at(stop).x, at(stop).y) == Tri::no) ++stop;
  out.cutBack = run.size() + 1 < stop;
  return out;
}

// Pass ends of the paper's surfaces, contour (the section curves' ends, centres r + R n, the
// bands half way to the neighbouring planes, unbounded beyond the outermost, steps as
// contour.cpp chooses them: half the gap, R / 64 to R / 4) and raster (lines e . c = w
// leaving the 3 x 3 in footprint, offset R, steps R / 8), balls of 0.25 and 1 in, run on up
// to kRunOnLength R: every run judged; the same ends with an unbounded band run on to the
// first vertex with nothing within R (or the length), with an empty band return nothing.
TEST(RunOnPastEnd, PaperSurfacesContourAndRasterEndsAgainstTheReference) {
  std::size_t runs = 0, vertices = 0, empty = 0, ambiguous = 0, cutBack = 0;
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = exampleSurface(name);
    const SurfaceDistance distance(s);
    const DropReference reference(s, 300);
    const Vec3 contourNormal = normalized(std::string(name) == "paper-1" ? Vec3{0.248, -0.969, 0.001}
                                                                         : Vec3{0.975, -0.221, -0.002});
    for (const double R : {0.25, 1.0}) {
      std::vector<RunOnCase> cases;
      // Contour ends.
      ContourOptions o;
      o.normal = contourNormal;
      o.toolRadius = R;
      o.spacing = 0.35;
      o.dropEnvelope = false;
      const ContourPaths contour = contourPaths(s, o);
      for (std::size_t k = 0; k < contour.sections.size(); ++k) {
        RunOnBand band{contour.normal, 0.0};
        const double w = contour.sections[k].offset;
        double gap = 4.0 * R;
        if (k > 0) band.lo = 0.5 * (contour.sections[k - 1].offset + w), gap = std::min(gap, w - contour.sections[k - 1].offset);
        if (k + 1 < contour.sections.size()) band.hi = 0.5 * (w + contour.sections[k + 1].offset), gap = std::min(gap, contour.sections[k + 1].offset - w);
        const double step = std::clamp(0.5 * gap, R / 64.0, R / 4.0);
        for (const SectionCurve& curve : contour.sections[k].section.curves) {
          if (curve.closed || curve.points.size() < 2) continue;
          const auto centre = [&](const SectionPoint& p) { return p.point + R * upwardNormal(s, p.patch, p.u, p.v); };
          const Vec3 first = centre(curve.points[0]), second = centre(curve.points[1]);
          const Vec3 last = centre(curve.points.back()), before = centre(curve.points[curve.points.size() - 2]);
          const std::string what = std::string(name) + " R " + std::to_string(R) + " contour plane " + std::to_string(k);
          cases.push_back({first, first - second, band, step, what + " start"});
          cases.push_back({last, last - before, band, step, what + " end"});
        }
      }
      // Raster lines leaving the footprint [0, 3]^2 at both ends.
      const double a = 0.3;
      const Vec3 e{-std::sin(a), std::cos(a), 0.0}, d{std::cos(a), std::sin(a), 0.0};
      for (double w = -0.3; w <= 2.6; w += 0.58) {
        // The line w e + t d inside the square for t in [t0, t1].
        double t0 = -kInf, t1 = kInf;
        for (const auto& [o1, d1] : {std::pair{w * e.x, d.x}, std::pair{w * e.y, d.y}}) {
          double lo = (0.0 - o1) / d1, hi = (3.0 - o1) / d1;
          if (lo > hi) std::swap(lo, hi);
          t0 = std::max(t0, lo), t1 = std::min(t1, hi);
        }
        if (!(t0 < t1)) continue;
        const RunOnBand band{e, R, w - 0.29, w + 0.29};
        const std::string what = std::string(name) + " R " + std::to_string(R) + " raster w " + std::to_string(w);
        cases.push_back({w * e + t1 * d, d, band, R / 8.0, what + " exit"});
        cases.push_back({w * e + t0 * d, -d, band, R / 8.0, what + " entry"});
      }
      for (RunOnCase& c : cases) {
        SCOPED_TRACE(c.what);
        const RunOnJudged judged = judgeRunOn(s, distance, reference, c, R, kRunOnLength * R);
        ++runs;
        vertices += judged.vertices;
        empty += judged.vertices == 0;
        ambiguous += judged.ambiguous;
        cutBack += judged.cutBack;
      }
      // Unbounded and empty bands at a few of the ends.
      for (std::size_t i = 0; i < cases.size(); i += 5) {
        RunOnCase c = cases[i];
        c.band.lo = -kInf, c.band.hi = kInf;
        c.what += " unbounded";
        judgeRunOn(s, distance, reference, c, R, kRunOnLength * R);
        c.band.lo = 1.0, c.band.hi = -1.0;
        EXPECT_TRUE(runOnPastEnd(distance, c.end, c.direction, R, c.band, c.step, kRunOnLength * R).empty()) << c.what;
      }
    }
  }
  std::printf("[          ] %zu run-ons judged, %zu vertices, %zu empty, %zu cut back to the band, %zu "
              "ambiguous\n", runs, vertices, empty, cutBack, ambiguous);
  EXPECT_GT(vertices, 100u);
  EXPECT_LT(empty, runs);
  EXPECT_GT(cutBack, 0u);  // the band's rule is exercised, not only the stop
  EXPECT_LE(ambiguous, runs / 10);
}


// The arguments are checked; a direction with no horizontal part has nothing to run on.
TEST(RunOnPastEnd, BadInputAndDegenerateArguments) {
  const Surface s = exampleSurface("paper-1");
  const SurfaceDistance distance(s);
  const Vec3 end{3.0, 1.5, 1.0}, along{1.0, 0.0, 0.0};
  const RunOnBand band{{0.0, 1.0, 0.0}, 0.25, 1.0, 2.0};
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.25, band, 0.0, 1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.25, band, -0.1, 1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.25, band, std::nan(""), 1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.25, band, 0.1, -1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.25, band, 0.1, kInf), Error);
  EXPECT_THROW(runOnPastEnd(distance, {std::nan(""), 1.5, 1.0}, along, 0.25, band, 0.1, 1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, {kInf, 0.0, 0.0}, 0.25, band, 0.1, 1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.0, band, 0.1, 1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, along, -0.25, band, 0.1, 1.0), Error);
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.25, band, 1e-8, 1.0), Error);  // 1e8 steps
  EnvelopeOptions coarse;
  coarse.depthTolerance = 0.3;  // not below R
  EXPECT_THROW(runOnPastEnd(distance, end, along, 0.25, band, 0.1, 1.0, coarse), Error);
  // No horizontal direction, or no room for a step: nothing.
  EXPECT_TRUE(runOnPastEnd(distance, end, {0.0, 0.0, 1.0}, 0.25, band, 0.1, 1.0).empty());
  EXPECT_TRUE(runOnPastEnd(distance, end, {0.0, 0.0, 0.0}, 0.25, band, 0.1, 1.0).empty());
  EXPECT_TRUE(runOnPastEnd(distance, end, along, 0.25, band, 0.1, 0.05).empty());
  EXPECT_TRUE(runOnPastEnd(distance, end, along, 0.25, band, 0.1, 0.0).empty());
  // Far from the surface: the first vertex has nothing within R.
  EXPECT_TRUE(runOnPastEnd(distance, {50.0, 50.0, 0.0}, along, 0.25, {}, 0.1, 1.0).empty());
  // dropLineRuns: a vertical direction and too many steps are errors too.
  EXPECT_THROW(dropLineRuns(distance, {0.0, 1.5, 0.0}, {0.0, 0.0, 1.0}, 0.0, 3.0, 0.25, band, 0.1), Error);
  EXPECT_THROW(dropLineRuns(distance, {0.0, 1.5, 0.0}, along, 0.0, 3.0, 0.25, band, 1e-7), Error);
  EXPECT_THROW(dropLineRuns(distance, {0.0, 1.5, 0.0}, along, 3.0, 0.0, 0.25, band, 0.1), Error);
  EXPECT_THROW(dropLineRuns(distance, {0.0, 1.5, 0.0}, along, 0.0, 3.0, -1.0, band, 0.1), Error);
  EXPECT_THROW(dropLineRuns(distance, {0.0, 1.5, 0.0}, along, 0.0, 3.0, 0.25, band, 0.0), Error);
}

// dropLineRuns along raster-like lines over and beyond the paper's surfaces (vertical planes
// e . c = w at a feed angle, the band offset R as raster's, some beyond the outermost plane
// with a band unbounded on that side): every vertex of a run at origin + (from + k step) h
// for consecutive k, on the envelope, touching inside the band (not judged clear or outside:
// the reference's verdicts with the proofs' slack); the vertices beside a run not certainly
// inside; every pair of neighbouring vertices certainly inside is in a run; a line far
// from the surface has no runs.
TEST(DropLineRuns, PaperSurfacesAgainstTheReference) {
  std::size_t lines = 0, runs = 0, vertices = 0;
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface s = exampleSurface(name);
    const SurfaceDistance distance(s);
    const DropReference reference(s, 300);
    const double eps = 1e-6 * surfaceScale(s);
    for (const double R : {0.25, 1.0}) {
      const double a = 0.9;
      const Vec3 e{-std::sin(a), std::cos(a), 0.0}, h{std::cos(a), std::sin(a), 0.0};
      // e . r over the square [0, 3]^2 spans [-3 sin a, 3 cos a]; lines from beyond one side to
      // beyond the other, the outer ones as raster's drop lines with one-sided bands.
      const double lo = -3.0 * std::sin(a), hi = 3.0 * std::cos(a);
      for (const double w : {lo - 0.6 * R, lo + 0.1, 0.5 * (lo + hi), hi - 0.2, hi + 0.5 * R}) {
        RunOnBand band{e, R, w - 0.15, w + 0.15};
        if (w < lo) band.lo = -kInf;
        if (w > hi) band.hi = kInf;
        const Vec3 origin = w * e;
        const double from = -1.0 - R, to = 5.0 + R, step = R / 6.0;
        const std::vector<std::vector<Vec3>> got = dropLineRuns(distance, origin, h, from, to, R, band, step);
        const std::string what = std::string(name) + " R " + std::to_string(R) + " w " + std::to_string(w);
        SCOPED_TRACE(what);
        ++lines;
        const auto steps = static_cast<std::size_t>(std::floor((to - from) / step));
        const auto at = [&](std::size_t k) { return origin + (from + double(k) * step) * h; };
        const BandJudge judge(s, reference, band, R, eps, distance.tolerance());
        // The verdicts per vertex, lazily: certainly inside (clear no, inside yes), certainly
        // not (clear yes or inside no), or maybe.
        std::vector<int> verdict(steps + 1, -2);  // -2 unknown, -1 not, 0 maybe, 1 inside
        std::vector<double> heights(steps + 1, std::nan(""));
        const auto judged = [&](std::size_t k) {
          if (verdict[k] != -2) return verdict[k];
          const Vec3 p = at(k);
          const Tri clear = judge.clear(p.x, p.y);
          if (clear == Tri::yes) return verdict[k] = -1;
          const double z = std::isnan(heights[k]) ? judge.height(p.x, p.y) : heights[k];
          const Tri inside = judge.inside({p.x, p.y, z});
          if (inside == Tri::no) return verdict[k] = -1;
          return verdict[k] = clear == Tri::no && inside == Tri::yes ? 1 : 0;
        };
        std::vector<bool> inRun(steps + 1, false);
        for (const std::vector<Vec3>& run : got) {
          ++runs;
          EXPECT_GE(run.size(), 2u);
          const double t = dot(run.front() - origin, h);
          const auto first = static_cast<std::size_t>(std::llround((t - from) / step));
          ASSERT_LE(first + run.size(), steps + 1);
          for (std::size_t i = 0; i < run.size(); ++i) {
            const std::size_t k = first + i;
            const std::string where = what + " vertex " + std::to_string(k);
            EXPECT_NEAR(run[i].x, at(k).x, 1e-12 * surfaceScale(s)) << where;
            EXPECT_NEAR(run[i].y, at(k).y, 1e-12 * surfaceScale(s)) << where;
            judge.expectOnEnvelope(run[i], where);
            heights[k] = run[i].z;
            EXPECT_NE(judged(k), -1) << where << ": not inside the band, or clear";
            EXPECT_FALSE(inRun[k]) << where << ": in two runs";
            inRun[k] = true;
            ++vertices;
          }
          if (first > 0) {
            EXPECT_NE(judged(first - 1), 1) << what << ": the run could start earlier";
          }
          if (first + run.size() <= steps) {
            EXPECT_NE(judged(first + run.size()), 1) << what << ": the run could go on";
          }
        }
        // Completeness, where the surface can be touched (within R of the square).
        for (std::size_t k = 0; k + 1 <= steps; ++k) {
          const Vec3 p = at(k);
          if (p.x < -R || p.x > 3.0 + R || p.y < -R || p.y > 3.0 + R) continue;
          if (judged(k) == 1 && judged(k + 1) == 1) {
            EXPECT_TRUE(inRun[k] && inRun[k + 1]) << what << ": vertices " << k << ", " << k + 1 << " inside, in no run";
          }
        }
      }
    }
    // Far from the surface: nothing.
    EXPECT_TRUE(dropLineRuns(distance, {40.0, 40.0, 0.0}, {1.0, 1.0, 0.0}, -5.0, 5.0, 0.25, {}, 0.05).empty());
  }
  std::printf("[          ] %zu lines, %zu runs, %zu vertices\n", lines, runs, vertices);
  EXPECT_GT(runs, lines / 2);
}


// The sag tolerance (EnvelopeOptions::sagTolerance) on paper-2 with R = 0.25 in and s =
// 2.5e-4 in (H / 4 for H = 0.001 in, as the CLI passes it): the scallop hull's raster passes
// (unlifted) and hand-made passes of a few far-apart vertices below the surface across its
// valleys (lifted onto the envelope, the moves between them halved until proven, so long
// proven chords bridge the valleys). On the lifted output, every straight move whose
// horizontal extent exceeds sqrt(8 R s) and whose midpoint stands over the surface (the
// reference's drop height finite there) has its midpoint at most s above the envelope, up to
// the envelope's own eps / 4 (the split compares with the lifted height, at most eps / 4 over
// the true one) and 1e-9 of the reference's convergence; every move is still proven (none
// unproven) and the sampled distance reference finds no centre deeper than eps. Without the
// option the same inputs leave such midpoints well above s: the check has something to catch.
// (The length is the horizontal one, as the envelope measures it: a steep move, such as a
// raster pass's rise off the surface, does not sag across the envelope however long it is.)
TEST(DropEnvelope, SagToleranceSplitsMovesWhereTheEnvelopeSags) {
  const Surface s = exampleSurface("paper-2");
  const SurfaceDistance distance(s);
  const DropReference reference(s, 300);
  const double R = 0.25, sag = 2.5e-4, scale = surfaceScale(s);
  const double shortest = std::sqrt(8.0 * R * sag);
  RasterOptions o;
  o.angleRad = 0.3;
  o.toolRadius = R;
  o.spacing = 0.3;
  o.dropEnvelope = false;
  const RasterPaths raster = rasterPaths(s, o);
  ToolPath lines;
  lines.toolRadius = R;
  const auto line = [&](Vec3 a, Vec3 b, int pieces) {
    ToolPass pass{a, {}, true};
    for (int k = 1; k <= pieces; ++k) pass.moves.push_back({MoveKind::line, a + (double(k) / pieces) * (b - a), {}, ArcPlane::xy, true});
    lines.passes.push_back(pass);
  };
  line({0.2, 0.2, -1.0}, {2.8, 2.8, -1.0}, 4);
  line({0.2, 2.8, -1.0}, {2.8, 0.2, -1.0}, 4);
  for (const double y : {0.8, 1.3, 1.9, 2.4}) line({0.1, y, -1.0}, {2.9, y, -1.0}, 4);
  struct Input {
    std::string name;
    const ToolPath* path;
    bool raster;
  };
  for (const Input& input : {Input{"raster", &raster.path, true}, Input{"lines", &lines, false}}) {
    SCOPED_TRACE(input.name);
    std::size_t judged[2] = {0, 0}, over[2] = {0, 0};
    double worst[2] = {0.0, 0.0};
    std::size_t movesOut[2] = {0, 0};
    for (const int on : {0, 1}) {
      EnvelopeOptions options;
      options.sagTolerance = on ? sag : 0.0;
      EnvelopeReport report;
      std::vector<std::vector<std::size_t>> moveMap;
      const ToolPath lifted = liftToDropEnvelope(distance, *input.path, options, report, &moveMap);
      movesOut[on] = report.movesOut;
      const double eps = report.depthTolerance;
      for (const ToolPass& pass : lifted.passes) {
        Vec3 at = pass.start;
        for (const ToolMove& move : pass.moves) {
          const Vec3 from = at;
          at = move.end;
          if (move.kind != MoveKind::line || !(std::hypot(at.x - from.x, at.y - from.y) > shortest)) continue;
          const Vec3 middle = 0.5 * (from + at);
          const double envelope = reference.refinedDrop(middle.x, middle.y, R).value;
          if (!std::isfinite(envelope)) continue;  // nothing below to lower it onto
          ++judged[on];
          const double excess = middle.z - envelope;
          worst[on] = std::max(worst[on], excess);
          if (excess > sag + 0.25 * eps + 1e-9 * scale) ++over[on];
        }
      }
      if (!on) continue;
      EXPECT_EQ(report.unprovenMoves, 0u);
      const auto cutting = [&](std::size_t pass, std::size_t move) {
        if (!input.raster) return true;
        const RasterPass& info = raster.passes[pass];
        return move >= info.linkMoves + info.entryMoves && move + info.exitMoves < input.path->passes[pass].moves.size();
      };
      judge(s, *input.path, lifted, moveMap, eps, input.raster ? 1e-4 * scale : 0.0, input.raster ? 3 : 1,
            input.name, cutting);
    }
    std::printf("[          ] %s: without the sag tolerance %zu moves, %zu long ones over the surface, %zu "
                "sagging more than s (worst %.3g); with s = %g: %zu moves, %zu long, %zu over (worst %.3g)\n",
                input.name.c_str(), movesOut[0], judged[0], over[0], worst[0], sag, movesOut[1], judged[1], over[1],
                worst[1]);
    EXPECT_EQ(over[1], 0u);
    EXPECT_GT(judged[1], 20u);
    if (!input.raster) {
      // The regression the option prevents: chords bridging the valleys (the raster's count
      // without it is mostly its links, which stand above the surface by design).
      EXPECT_GT(over[0], 3u);
      EXPECT_GT(worst[0], 40.0 * sag);
    }
  }
}

// Found while writing the test above: the sag rule applied to every straight move, so with a
// sag tolerance the raster's links, which rise to their link height L, cross at L and come
// down (raster.hpp's contract; RasterPass::linkHeight), had the crossing's midpoint lowered
// onto the envelope: the link dived to the surface between the passes (paper-1: 86 of 86
// links, by up to 0.229 in). The strategies now name their cutting moves
// (EnvelopeOptions::sagMoves), and the rule applies to those only.
TEST(DropEnvelope, RasterLinksStayAtTheirHeightWithASagTolerance) {
  const Surface s = exampleSurface("paper-1");
  RasterOptions o;
  o.bestAngle = true;
  o.toolRadius = 0.25;
  o.spacing = 0.3;
  o.sagTolerance = 2.5e-4;
  const RasterPaths r = rasterPaths(s, o);
  std::size_t links = 0;
  for (std::size_t p = 0; p < r.passes.size(); ++p) {
    const RasterPass& info = r.passes[p];
    if (info.linkMoves == 0) continue;
    ++links;
    // The link's vertices after the rise and before the descent stand at L.
    for (std::size_t m = 0; m + 1 < info.linkMoves; ++m)
      EXPECT_GE(r.path.passes[p].moves[m].end.z, info.linkHeight - 1e-9) << "pass " << p << " link move " << m;
  }
  EXPECT_GT(links, 5u);
}
}  // namespace
}  // namespace scallop
