// The drop envelope (envelope.hpp) and the segment clearance test under it (gouge.hpp),
// judged by tests/distance_reference.hpp: every patch sampled on a grid and refined by a
// derivative-free pattern search, written independently of gouge.cpp. Its distance is
// attained by a surface point, so it is never below the true distance.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "distance_reference.hpp"
#include "scallop/contour.hpp"
#include "scallop/cut_simulation.hpp"
#include "scallop/envelope.hpp"
#include "scallop/error.hpp"
#include "scallop/gouge.hpp"
#include "scallop/optimal_slicing.hpp"
#include "scallop/raster.hpp"
#include "scallop/surface.hpp"

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

// The acceptance: the paper's surfaces, both strategies, balls from 0.05 to 1 in, cut
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

}  // namespace
}  // namespace scallop
