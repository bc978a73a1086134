// Tests of linking.hpp: the passes are all there, once each, as the strategy made them (run
// backwards or started elsewhere on a loop only where allowed); every link the linker makes
// is clear by an independent judge; the paper-1 contour plan's air time falls by >= 80 %.
//
// The judge: the ball's centre sampled every R / 16 along each move of each link (the rise,
// the traverse and the descent of a local retract; the straight feed of a direct link; the
// descent into the first pass), its distance to the surface taken from
// tests/support/distance_reference.hpp (a dense grid and a pattern search, sharing nothing with
// gouge.hpp's branch and bound). The reference distance is attained by a surface point, so
// when it says a centre is too close, it is. Limits: R - a at a move that starts or ends at a
// pass end whose own depth is a (the contract: never deeper than at the ends, plus epsilon),
// R on the traverse (at or above the proven height bound every centre is >= R away). The
// allowance a is recomputed with the reference; both distances carry errors up to the
// linker's distance tolerance epsilon / 8 (gouge.hpp), allowed for.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "support/distance_reference.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/error.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/paths/linking.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/raster.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

Vec3 endOf(const ToolPass& pass) { return pass.moves.empty() ? pass.start : pass.moves.back().end; }

double referenceDistance(const Surface& surface, Vec3 c) {
  return reference::referenceDistance(surface, c, 32, 4).refined;
}

// A bicubic graph patch p_jk = (k, j, z_jk) inches, heights random in [-amplitude, amplitude].
Surface randomGraphPatch(std::mt19937_64& rng, double amplitude) {
  std::uniform_real_distribution<double> z(-amplitude, amplitude);
  BezierPatch p;
  for (int j = 0; j <= 3; ++j)
    for (int k = 0; k <= 3; ++k) p.control.push_back(Vec3{double(k), double(j), z(rng)});
  Surface s;
  s.units = Units::inch;
  s.patches.push_back(p);
  return s;
}

ToolPath contourPath(const Surface& surface, Vec3 normal, double spacing, double radius) {
  ContourOptions options;
  options.normal = normal;
  options.spacing = spacing;
  options.toolRadius = radius;
  return contourPaths(surface, options).path;
}

ToolPath optimalContourPath(const Surface& surface, double radius, double scallopHeight) {
  const OptimalSlicing orientation = optimalSlicing(surface);
  Vec3 normal = orientation.normal;
  if (normal.z < 0.0) normal = -normal;
  return contourPath(surface, normal,
                     spacingForScallopHeight(radius, scallopHeight, orientation.certifiedAlphaRad),
                     radius);
}

// Every vertex of a pass (start, then each move's end) with, per move, its arc data.
struct Vertices {
  std::vector<Vec3> points;
  std::vector<ToolMove> moves;
};
Vertices verticesOf(const ToolPass& pass) {
  Vertices v;
  v.points.push_back(pass.start);
  for (const ToolMove& m : pass.moves) {
    v.points.push_back(m.end);
    v.moves.push_back(m);
  }
  return v;
}

bool sameArc(const ToolMove& a, const ToolMove& b, bool flipped) {
  if (a.kind != b.kind) return false;
  if (a.kind == MoveKind::line) return true;
  return a.center == b.center && a.plane == b.plane && (a.clockwise != b.clockwise) == flipped;
}

// Output pass `out` is input pass `in` as it is, run backwards, or (a closed pass) started at
// another vertex: checked on the vertices themselves.
::testing::AssertionResult samePass(const ToolPass& in, const ToolPass& out, bool reversed) {
  const Vertices a = verticesOf(in);
  const Vertices b = verticesOf(out);
  if (a.points.size() != b.points.size()) return ::testing::AssertionFailure() << "vertex count";
  const std::size_t n = a.moves.size();
  if (reversed) {
    for (std::size_t i = 0; i <= n; ++i)
      if (!(a.points[i] == b.points[n - i])) return ::testing::AssertionFailure() << "reversed vertex " << i;
    for (std::size_t i = 0; i < n; ++i)
      if (!sameArc(a.moves[i], b.moves[n - 1 - i], true))
        return ::testing::AssertionFailure() << "reversed move " << i;
    return ::testing::AssertionSuccess();
  }
  const bool closed = n >= 2 && a.points.front() == a.points.back();
  for (std::size_t shift = 0; shift < (closed ? n : 1); ++shift) {
    bool match = true;
    for (std::size_t i = 0; i < n && match; ++i)
      match = a.points[(i + shift) % n] == b.points[i] && sameArc(a.moves[(i + shift) % n], b.moves[i], false);
    if (match && (closed || a.points[n] == b.points[n])) return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "no rotation of the input matches";
}

// Output pass i without the moves the linker put in front of it (an envelope link).
ToolPass withoutLink(const LinkedPath& linked, std::size_t i) {
  ToolPass pass = linked.path.passes[i];
  const std::size_t k = i < linked.linkMoves.size() ? linked.linkMoves[i] : 0;
  if (k == 0) return pass;
  pass.start = pass.moves[k - 1].end;
  pass.moves.erase(pass.moves.begin(), pass.moves.begin() + static_cast<std::ptrdiff_t>(k));
  return pass;
}

struct JudgeResult {
  double worstExcess = -1e300;  // max over samples of (limit - reference distance)
  std::size_t samples = 0;
  std::string where;
};

void sampleSegment(const Surface& surface, Vec3 a, Vec3 b, double limit, double step,
                   const std::string& what, JudgeResult& result) {
  const double length = norm(b - a);
  const int count = std::max(1, static_cast<int>(std::ceil(length / step)));
  for (int i = 0; i <= count; ++i) {
    const Vec3 c = a + (b - a) * (static_cast<double>(i) / count);
    const double excess = limit - referenceDistance(surface, c);
    ++result.samples;
    if (excess > result.worstExcess) {
      result.worstExcess = excess;
      result.where = what;
    }
  }
}

// The judge (see the file's comment) on every link the linker made.
JudgeResult judgeLinks(const Surface& surface, const ToolPath& input, const LinkedPath& linked) {
  const double radius = linked.path.toolRadius;
  const double epsilon = linked.stats.gougeAllowance;
  const double step = radius / 16.0;
  const auto allowance = [&](Vec3 c) {
    return std::max(radius - referenceDistance(surface, c), 0.0) + epsilon;
  };
  double top = -1e300;
  for (const BezierPatch& p : surface.patches)
    for (const Vec3& c : p.control) top = std::max(top, c.z);
  JudgeResult result;
  const std::vector<ToolPass>& passes = linked.path.passes;
  for (std::size_t i = 0; i < passes.size(); ++i) {
    const ToolPass& pass = passes[i];
    const Vec3 s = pass.start;
    const std::string where = "link into pass " + std::to_string(i);
    if (i == 0) {
      if (pass.retract)
        sampleSegment(surface, {s.x, s.y, top + radius + 0.1}, s, radius - allowance(s), step,
                      where + " (first descent)", result);
      continue;
    }
    const bool strategyLink = !input.passes[linked.origin[i]].retractBefore;
    if (strategyLink) continue;  // the strategy's own, left alone
    const Vec3 e = endOf(passes[i - 1]);
    const std::size_t linkMoves = linked.linkMoves.at(i);
    if (linkMoves > 0) {
      // Over the drop envelope: every move within epsilon of the surface at most.
      EXPECT_FALSE(pass.retractBefore) << where;
      EXPECT_TRUE(pass.start == e) << where << " does not start at the previous end";
      Vec3 at = s;
      for (std::size_t m = 0; m < linkMoves; ++m) {
        sampleSegment(surface, at, pass.moves[m].end, radius - epsilon, step, where + " (over the envelope)", result);
        at = pass.moves[m].end;
      }
    } else if (!pass.retractBefore) {
      sampleSegment(surface, e, s, radius - std::max(allowance(e), allowance(s)), step,
                    where + " (direct)", result);
    } else if (pass.retract) {
      const double h = pass.retract->height;
      sampleSegment(surface, e, {e.x, e.y, h}, radius - allowance(e), step, where + " (rise)", result);
      sampleSegment(surface, {e.x, e.y, h}, {s.x, s.y, h}, radius, step, where + " (traverse)", result);
      sampleSegment(surface, {s.x, s.y, h}, s, radius - allowance(s), step, where + " (descent)", result);
    }
  }
  return result;
}

// Everything the linker promises about one path.
void expectLinkedWell(const Surface& surface, const ToolPath& input, const LinkOptions& options,
                      const std::string& name) {
  SCOPED_TRACE(name);
  const LinkedPath linked = linkToolPath(surface, input, options);
  const std::size_t n = input.passes.size();
  ASSERT_EQ(linked.path.passes.size(), n);
  ASSERT_EQ(linked.origin.size(), n);
  ASSERT_EQ(linked.reversed.size(), n);
  // A permutation: no pass dropped or duplicated.
  std::vector<std::size_t> sorted = linked.origin;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::size_t> identity(n);
  std::iota(identity.begin(), identity.end(), std::size_t{0});
  EXPECT_EQ(sorted, identity);
  std::size_t reversedCount = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const ToolPass& in = input.passes[linked.origin[i]];
    EXPECT_TRUE(samePass(in, withoutLink(linked, i), linked.reversed[i])) << "pass " << i;
    if (linked.reversed[i]) ++reversedCount;
    if (options.direction == PassDirection::keep) {
      EXPECT_FALSE(linked.reversed[i]);
    }
    // The strategy's own links travel with their pass, behind the same predecessor.
    if (i > 0 && !in.retractBefore) {
      EXPECT_EQ(linked.origin[i], linked.origin[i - 1] + 1) << "pass " << i;
      EXPECT_FALSE(linked.path.passes[i].retractBefore);
    }
  }
  EXPECT_EQ(reversedCount, linked.stats.reversedPasses);
  // Every link is of one kind.
  const LinkStats& st = linked.stats;
  EXPECT_EQ(st.directLinks + st.localRetracts + st.unprovenLinks + st.strategyLinks, n - 1);
  std::size_t direct = 0, local = 0, safe = 0;
  for (std::size_t i = 1; i < n; ++i) {
    const ToolPass& p = linked.path.passes[i];
    if (!input.passes[linked.origin[i]].retractBefore) continue;
    if (!p.retractBefore) ++direct;
    else if (p.retract) ++local;
    else ++safe;
  }
  EXPECT_EQ(direct, st.directLinks);
  EXPECT_EQ(local, st.localRetracts);
  EXPECT_EQ(safe, st.unprovenLinks);
  const JudgeResult judge = judgeLinks(surface, input, linked);
  const double slack = st.gougeAllowance / 8.0 * 2.0 + 1e-12 * surfaceScale(surface);
  EXPECT_LE(judge.worstExcess, slack) << judge.where << " (" << judge.samples << " samples)";
  // The relinked program is valid G-code (local retracts below the safe height).
  GcodeOptions g;
  double top = -1e300;
  for (const BezierPatch& p : surface.patches)
    for (const Vec3& c : p.control) top = std::max(top, c.z);
  for (const ToolPass& p : input.passes) {
    top = std::max(top, p.start.z - input.toolRadius);
    for (const ToolMove& m : p.moves) top = std::max(top, m.end.z - input.toolRadius);
  }
  g.safeHeight = top + (surface.units == Units::inch ? 0.2 : 5.0);
  g.feedRate = 40.0;
  g.plungeFeedRate = 15.0;
  g.spindleRpm = 0.0;
  EXPECT_NO_THROW((void)gcodeProgram(linked.path, g));
}

void expectContourOnNStarLinkedWell(const char* name) {
  const Surface surface = exampleSurface(name);
  for (const double radius : {0.1, 0.25, 0.5}) {
    const ToolPath path = optimalContourPath(surface, radius, 0.004);
    expectLinkedWell(surface, path, {}, std::string(name) + " R " + std::to_string(radius));
  }
}

TEST(Linking, Paper1ContourSeveralRadii) { expectContourOnNStarLinkedWell("paper-1"); }
TEST(Linking, Paper2ContourSeveralRadii) { expectContourOnNStarLinkedWell("paper-2"); }

TEST(Linking, PaperSurfacesHorizontalContoursWithLoops) {
  // Horizontal planes: paper-1's summit gives closed sections, started at any vertex.
  const Surface surface = exampleSurface("paper-1");
  const ToolPath path = contourPath(surface, {0, 0, 1}, 0.05, 0.25);
  expectLinkedWell(surface, path, {}, "paper-1 horizontal");
  const LinkedPath linked = linkToolPath(surface, path);
  EXPECT_GT(linked.stats.rotatedLoops, 0u);
  LinkOptions oneWay;
  oneWay.direction = PassDirection::keep;
  expectLinkedWell(surface, path, oneWay, "paper-1 horizontal, one way");
  EXPECT_EQ(linkToolPath(surface, path, oneWay).stats.reversedPasses, 0u);
}

TEST(Linking, PaperSurfacesRaster) {
  for (const char* name : {"paper-1", "paper-2"}) {
    const Surface surface = exampleSurface(name);
    RasterOptions options;
    options.bestAngle = true;
    options.toolRadius = 0.25;
    options.spacing = 0.1;
    const RasterPaths raster = rasterPaths(surface, options);
    expectLinkedWell(surface, raster.path, {}, std::string(name) + " raster");
    LinkOptions keepOrder;
    keepOrder.reorder = false;
    expectLinkedWell(surface, raster.path, keepOrder, std::string(name) + " raster, order kept");
  }
}

// Two random graph patches side by side with a 1 in gap along x: raster planes across the
// gap have two chains, the second entered from the safe height by the strategy, which the
// linker relinks (direct feeds across the gap or local retracts over it).
TEST(Linking, RasterAcrossAGap) {
  std::mt19937_64 rng(7);
  Surface s = randomGraphPatch(rng, 0.5);
  Surface t = randomGraphPatch(rng, 0.5);
  for (Vec3& p : t.patches[0].control) p.x += 4.0;
  s.patches.push_back(t.patches[0]);
  for (const double deg : {0.0, 10.0}) {
    RasterOptions options;
    options.angleRad = deg * std::numbers::pi / 180.0;
    options.toolRadius = 0.25;
    options.spacing = 0.25;
    const ToolPath path = rasterPaths(s, options).path;
    expectLinkedWell(s, path, {}, "gap at " + std::to_string(deg));
    const LinkedPath linked = linkToolPath(s, path);
    EXPECT_GT(linked.stats.directLinks + linked.stats.localRetracts, 0u)
        << deg << " deg: " << linked.stats.unprovenLinks << " unproven, "
        << linked.stats.strategyLinks << " strategy links";
  }
}

void expectTeapotPartLinkedWell(const char* name) {
  const Surface surface = exampleSurface(name);
  for (const double radius : {0.1, 0.3}) {
    const ToolPath path = contourPath(surface, {0, 0, 1}, 0.4, radius);
    expectLinkedWell(surface, path, {}, std::string(name) + " R " + std::to_string(radius));
  }
}

TEST(Linking, TeapotBodyAndLid) {
  expectTeapotPartLinkedWell("teapot-body");
  expectTeapotPartLinkedWell("teapot-lid");
}
TEST(Linking, TeapotSpoutAndHandle) {
  expectTeapotPartLinkedWell("teapot-spout");
  expectTeapotPartLinkedWell("teapot-handle");
}

TEST(Linking, RandomSurfaces) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 6; ++trial) {
    const Surface surface = randomGraphPatch(rng, 1.2);
    const double radius = trial % 2 == 0 ? 0.2 : 0.45;
    const std::string name = "random " + std::to_string(trial);
    expectLinkedWell(surface, contourPath(surface, {0, 0, 1}, 0.12, radius), {}, name + " contour");
    RasterOptions options;
    options.angleRad = 0.3 + trial;
    options.toolRadius = radius;
    options.spacing = 0.15;
    expectLinkedWell(surface, rasterPaths(surface, options).path, {}, name + " raster");
  }
}

// The target: the paper-1 contour plan (R = 0.25 in, H = 0.001 in, the G-code
// writer's defaults: feeds 40 and 15 in/min, safe height 0.2 in over the control points;
// rapid 200 in/min) spends at least 80 % less time off the cut once linked.
TEST(Linking, Paper1ContourAirTimeFallsByEightyPercent) {
  const Surface surface = exampleSurface("paper-1");
  const ToolPath path = optimalContourPath(surface, 0.25, 0.001);
  const LinkedPath linked = linkToolPath(surface, path);
  double top = -1e300;
  for (const Vec3& c : surface.patches[0].control) top = std::max(top, c.z);
  GcodeOptions g;
  g.safeHeight = top + 0.2;
  g.feedRate = 40.0;
  g.plungeFeedRate = 15.0;
  g.spindleRpm = 0.0;
  const GcodeMotion before = gcodeMotion(path, g, 200.0);
  const GcodeMotion after = gcodeMotion(linked.path, g, 200.0);
  const double airBefore = before.rapidMinutes + before.plungeMinutes;
  const double airAfter = after.rapidMinutes + after.plungeMinutes;
  EXPECT_LE(airAfter, 0.2 * airBefore) << airBefore << " -> " << airAfter << " min";
  // Cutting is the same passes, plus the direct links fed at cutting height.
  EXPECT_NEAR(after.feedLength, before.feedLength + linked.stats.directLinkLength,
              1e-9 * before.feedLength);
  EXPECT_EQ(linked.stats.unprovenLinks, 0u);
}

// The judge itself catches what it is there to catch: links made wrong on purpose (a
// traverse lowered to the pass's start height over paper-1's convex top; a direct feed
// straight through the surface) are found too close.
TEST(Linking, JudgeCatchesBadLinks) {
  const Surface surface = exampleSurface("paper-1");
  const ToolPath path = optimalContourPath(surface, 0.25, 0.004);
  LinkedPath linked = linkToolPath(surface, path);
  LinkedPath lowered = linked;
  std::size_t changed = 0;
  // Every link after the first made a local retract at the pass's start height (the linker
  // made none here: its feeds over the envelope serve every link).
  for (std::size_t i = 1; i < lowered.path.passes.size(); ++i) {
    ToolPass pass = withoutLink(lowered, i);
    if (!path.passes[lowered.origin[i]].retractBefore) continue;  // the strategy's own link
    pass.retractBefore = true;
    pass.retract = LocalRetract{pass.start.z, 0.0};
    lowered.path.passes[i] = pass;
    lowered.linkMoves[i] = 0;
    ++changed;
  }
  ASSERT_GT(changed, 0u);
  const JudgeResult low = judgeLinks(surface, path, lowered);
  EXPECT_GT(low.worstExcess, 1e-3) << low.where;
  LinkedPath through = linked;
  // The last pass fed straight from the first pass's end: across the whole part.
  std::swap(through.path.passes[1], through.path.passes.back());
  std::swap(through.origin[1], through.origin.back());
  std::swap(through.linkMoves[1], through.linkMoves.back());
  // The other links over the envelope now lead from the wrong ends: safe-height retracts.
  for (std::size_t i = 1; i < through.path.passes.size(); ++i) {
    if (through.linkMoves[i] == 0) continue;
    through.path.passes[i] = withoutLink(through, i);
    through.path.passes[i].retractBefore = true;
    through.path.passes[i].retract.reset();
    through.linkMoves[i] = 0;
  }
  through.path.passes[1].retractBefore = false;
  through.path.passes[1].retract.reset();
  const JudgeResult cut = judgeLinks(surface, path, through);
  EXPECT_GT(cut.worstExcess, 1e-3) << cut.where;
}

TEST(Linking, Deterministic) {
  const Surface surface = exampleSurface("paper-2");
  const ToolPath path = optimalContourPath(surface, 0.25, 0.002);
  const LinkedPath a = linkToolPath(surface, path);
  const LinkedPath b = linkToolPath(surface, path);
  EXPECT_EQ(a.origin, b.origin);
  GcodeOptions g;
  g.safeHeight = 5.0;
  g.feedRate = 40.0;
  g.plungeFeedRate = 15.0;
  g.spindleRpm = 0.0;
  EXPECT_EQ(gcodeProgram(a.path, g), gcodeProgram(b.path, g));
}

void expectLinkError(const Surface& surface, const ToolPath& path, const LinkOptions& options,
                     const std::vector<std::string>& fragments) {
  try {
    (void)linkToolPath(surface, path, options);
    ADD_FAILURE() << "no error; expected one mentioning " << fragments.front();
  } catch (const Error& e) {
    for (const std::string& f : fragments)
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what() << " lacks " << f;
  }
}

TEST(Linking, BadInputNamesTheProblem) {
  const Surface surface = exampleSurface("paper-1");
  const ToolPath path = contourPath(surface, {0, 0, 1}, 0.2, 0.25);
  LinkOptions o;
  o.clearance = -1.0;
  expectLinkError(surface, path, o, {"clearance", "-1"});
  o = {};
  o.plunge = std::nan("");
  expectLinkError(surface, path, o, {"plunge", "nan"});
  o = {};
  o.maxOrderingWork = 10.0;
  expectLinkError(surface, path, o, {"maxOrderingWork", "reorder = false"});
  ToolPath mm = path;
  mm.units = Units::millimetre;
  expectLinkError(surface, mm, {}, {"units (mm) differ from the surface's (in)"});
  ToolPath noRadius = path;
  noRadius.toolRadius = 0.0;
  expectLinkError(surface, noRadius, {}, {"tool radius", "0"});
  ToolPath notFinite = path;
  notFinite.passes[1].moves[0].end.x = std::nan("");
  expectLinkError(surface, notFinite, {}, {"pass 1", "not finite"});
  EXPECT_TRUE(linkToolPath(surface, ToolPath{Units::inch, 0.25, {}}).path.passes.empty());
}

}  // namespace
}  // namespace scallop
