// scallop-bench, tool paths: the main job (`scallop plan`) on each example surface for both
// strategies, and plane sections per second.
//   BM_PlanContour/<surface>  N* (optimalSlicing) -> contour paths at 0.001 in scallops ->
//                             G-code: what `scallop plan` computes, without the figures
//   BM_PlanRaster/<surface>   best feed angle -> raster paths (scallop hull per section) ->
//                             gouge check every R / 10 -> G-code
//   BM_PlaneSection/<surface> one section by a plane z = c, c cycling through 64 levels over
//                             the surface's height: sections per second
//   BM_PlanRaster/<surface>/0 the same without the drop envelope (the hull's in-plane paths,
//                             which gouge): what lifting costs, in the same run
//   BM_DropEnvelope/<surface>/<strategy>  liftToDropEnvelope alone on the unlifted contour
//                             (0) or raster (1) plan's path (made outside the loop); counters:
//                             moves in and out, clearance proofs, proofs per second
//   BM_LinkContour/<surface>  linkToolPath on the contour plan's path (made once, outside
//                             the loop): ordering and proven links, per pass
//   BM_LinkRaster/<surface>   the same on the raster plan's path
//   BM_DropCutter/<surface>/<warm>  DropCutter heights (envelope.hpp) on a 100 x 100 grid over
//                             the surface's footprint grown by R, row by row: one cutter for
//                             the grid (1: each point seeded by the last contact) or a new one
//                             per point (0: cold); points per second
//   BM_DistanceManyPatches/<N>  SurfaceDistance::closest from 4,096 points (fixed seed) within
//                             0.5 in of a surface of N translated copies of paper-1's patch
//                             side by side (on a 3 in grid): queries per second as the
//                             surface grows (the hierarchy of patch boxes: about flat in N;
//                             a scan of every patch's root cell would fall as 1 / N)
//   BM_ClearanceLongPatch/<S>/<cut>  SurfaceDistance::segmentClearance of 4,096 segments
//                             (fixed seed) 0.05 in long, tangent to the offset at R = 1/4 in
//                             of paper-1's patch stretched S times along x, clearance R - 1e-4:
//                             the drop envelope's proofs. cut 1: long patches cut into pieces
//                             (gouge.hpp's Pieces, the default), 0: searched whole, in the
//                             same run; proofs per second and cells per proof
//   BM_PatchJet/<d>/<one>     r and its derivatives to second order at 4,096 points (fixed
//                             seed) of a random patch of bidegree (d, d): point() (de
//                             Casteljau) then derivativesToSecondOrder (one 0: what the drop
//                             envelope does on a bicubic patch), or both from one pass of
//                             basis sums (one 1: what it and the distance search's Newton
//                             steps do on any other); evaluations per second
//   BM_TrimMayMeet/<k>/<clip>  mayMeet of 4,096 boxes of side 2^-k near a circle of three
//                             rational quadratic arcs (the trimmed disk's trim), against each
//                             arc: Bezier clipping (clip 1, mayMeet) or halving alone (0, its
//                             method before, detail::mayMeetByHalving); boxes per second

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/face_trim.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/paths/envelope.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/paths/linking.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/raster.hpp"
#include "scallop/paths/section.hpp"
#include "scallop/geometry/surface.hpp"

namespace {

constexpr double kToolRadius = 0.25;       // inches, as the paper's Table 1
constexpr double kScallopHeight = 0.001;   // inches, scallop plan's default

const char* surfaceName(const benchmark::State& state) {
  return state.range(0) == 1 ? "paper-1" : "paper-2";
}

scallop::GcodeOptions gcodeOptions() {
  scallop::GcodeOptions options;
  options.safeHeight = 3.0;
  options.feedRate = 40.0;
  options.plungeFeedRate = 15.0;
  options.spindleRpm = 10000.0;
  return options;
}

void BM_PlanContour(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state));
  std::size_t passes = 0;
  for (auto _ : state) {
    const scallop::OptimalSlicing orientation = scallop::optimalSlicing(surface);
    scallop::ContourOptions options;
    options.normal = orientation.normal;
    options.toolRadius = kToolRadius;
    options.spacing = scallop::spacingForScallopHeight(kToolRadius, kScallopHeight,
                                                       orientation.certifiedAlphaRad);
    const scallop::ContourPaths paths = scallop::contourPaths(surface, options);
    const std::string gcode = scallop::gcodeProgram(paths.path, gcodeOptions());
    benchmark::DoNotOptimize(gcode.data());
    passes = paths.path.passes.size();
  }
  state.counters["passes"] = static_cast<double>(passes);
  state.SetLabel(surfaceName(state));
}

void BM_PlanRaster(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state));
  std::size_t passes = 0;
  double depth = 0.0;
  for (auto _ : state) {
    scallop::RasterOptions options;
    options.dropEnvelope = state.range(1) != 0;
    options.bestAngle = true;
    options.toolRadius = kToolRadius;
    options.scallopHeight = kScallopHeight;
    const scallop::RasterPaths paths = scallop::rasterPaths(surface, options);
    const scallop::GougeReport gouge = scallop::gougeCheck(surface, paths.path, kToolRadius / 10.0);
    const std::string gcode = scallop::gcodeProgram(paths.path, gcodeOptions());
    benchmark::DoNotOptimize(gcode.data());
    passes = paths.path.passes.size();
    depth = gouge.maxDepth;
  }
  state.counters["passes"] = static_cast<double>(passes);
  state.counters["gouge_in"] = depth;
  state.SetLabel(surfaceName(state));
}

// The contour plan's path (N*, the paper's spacing for H), lifted or not.
scallop::ToolPath contourPlanPath(const scallop::Surface& surface, bool dropEnvelope = true) {
  const scallop::OptimalSlicing orientation = scallop::optimalSlicing(surface);
  scallop::ContourOptions options;
  options.normal = orientation.normal.z < 0.0 ? -orientation.normal : orientation.normal;
  options.toolRadius = kToolRadius;
  options.spacing = scallop::spacingForScallopHeight(kToolRadius, kScallopHeight,
                                                     orientation.certifiedAlphaRad);
  options.dropEnvelope = dropEnvelope;
  return scallop::contourPaths(surface, options).path;
}

// The raster plan's path (best angle, spacing for H), lifted or not.
scallop::ToolPath rasterPlanPath(const scallop::Surface& surface, bool dropEnvelope = true) {
  scallop::RasterOptions options;
  options.bestAngle = true;
  options.toolRadius = kToolRadius;
  options.scallopHeight = kScallopHeight;
  options.dropEnvelope = dropEnvelope;
  return scallop::rasterPaths(surface, options).path;
}

void BM_DropEnvelope(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state));
  const scallop::ToolPath path =
      state.range(1) == 0 ? contourPlanPath(surface, false) : rasterPlanPath(surface, false);
  const scallop::SurfaceDistance distance(surface);
  scallop::EnvelopeReport report;
  for (auto _ : state) {
    const scallop::ToolPath lifted = scallop::liftToDropEnvelope(distance, path, {}, report);
    benchmark::DoNotOptimize(lifted.passes.data());
  }
  state.counters["moves_in"] = static_cast<double>(report.movesIn);
  state.counters["moves_out"] = static_cast<double>(report.movesOut);
  state.counters["proofs"] = static_cast<double>(report.proofs);
  state.counters["proofs_per_s"] = benchmark::Counter(static_cast<double>(report.proofs),
                                                      benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::string(surfaceName(state)) + (state.range(1) == 0 ? " contour" : " raster"));
}

void BM_PlaneSection(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state));
  double lo = 1e300, hi = -1e300;
  for (const scallop::Vec3& p : surface.patches[0].control) lo = std::min(lo, p.z), hi = std::max(hi, p.z);
  std::size_t level = 0;
  for (auto _ : state) {
    const double z = lo + (hi - lo) * (static_cast<double>(level++ % 64) + 0.5) / 64.0;
    const scallop::PlaneSection section = scallop::planeSection(surface, {0, 0, 1}, z, 3e-4);
    benchmark::DoNotOptimize(section.curves.data());
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(surfaceName(state));
}




void linkBenchmark(benchmark::State& state, const scallop::Surface& surface,
                   const scallop::ToolPath& path) {
  scallop::LinkStats stats;
  for (auto _ : state) {
    const scallop::LinkedPath linked = scallop::linkToolPath(surface, path);
    benchmark::DoNotOptimize(linked.path.passes.data());
    stats = linked.stats;
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(path.passes.size()));
  state.counters["passes"] = static_cast<double>(path.passes.size());
  state.counters["direct"] = static_cast<double>(stats.directLinks);
  state.counters["local"] = static_cast<double>(stats.localRetracts);
  state.counters["unproven"] = static_cast<double>(stats.unprovenLinks);
  state.SetLabel(surfaceName(state));
}

void BM_LinkContour(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state));
  linkBenchmark(state, surface, contourPlanPath(surface));
}

void BM_LinkRaster(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state));
  linkBenchmark(state, surface, rasterPlanPath(surface));
}

}  // namespace

void BM_DropCutter(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state));
  const scallop::SurfaceDistance distance(surface);
  const bool warm = state.range(1) == 1;
  constexpr int kGrid = 100;
  double sum = 0.0;
  for (auto _ : state) {
    std::optional<scallop::DropCutter> cutter;
    if (warm) cutter.emplace(distance, kToolRadius);
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i) {
        if (!warm) cutter.emplace(distance, kToolRadius);
        const double x = -kToolRadius + (3.0 + 2.0 * kToolRadius) * i / (kGrid - 1.0);
        const double y = -kToolRadius + (3.0 + 2.0 * kToolRadius) * j / (kGrid - 1.0);
        sum += cutter->height(x, y);
      }
  }
  benchmark::DoNotOptimize(sum);
  state.counters["points_per_s"] = benchmark::Counter(double(kGrid * kGrid), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(std::string(surfaceName(state)) + (warm ? " warm" : " cold"));
}

void BM_DistanceManyPatches(benchmark::State& state) {
  const auto copies = static_cast<std::size_t>(state.range(0));
  const scallop::BezierPatch one = scallop::exampleSurface("paper-1").patches.front();
  scallop::Surface surface;
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(copies))));
  for (std::size_t i = 0; i < copies; ++i) {
    scallop::BezierPatch patch = one;
    const scallop::Vec3 shift{3.0 * static_cast<double>(i % side), 3.0 * static_cast<double>(i / side), 0.0};
    for (scallop::Vec3& p : patch.control) p = p + shift;
    surface.patches.push_back(std::move(patch));
  }
  const scallop::SurfaceDistance distance(surface);
  std::mt19937_64 random(14);
  std::uniform_real_distribution<double> across(0.0, 3.0 * static_cast<double>(side));
  std::uniform_real_distribution<double> up(1.5, 2.0);
  std::vector<scallop::Vec3> queries(4096);
  for (scallop::Vec3& q : queries) q = {across(random), across(random), up(random)};
  double sum = 0.0;
  for (auto _ : state)
    for (const scallop::Vec3& q : queries) sum += distance.closest(q).distance;
  benchmark::DoNotOptimize(sum);
  state.counters["queries_per_s"] =
      benchmark::Counter(static_cast<double>(queries.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(fmt::format("{} patches", copies));
}

void BM_ClearanceLongPatch(benchmark::State& state) {
  const double stretch = static_cast<double>(state.range(0));
  scallop::Surface surface = scallop::exampleSurface("paper-1");
  for (scallop::Vec3& p : surface.patches.front().control) p.x *= stretch;
  scallop::DistanceOptions options;
  options.cutLongPatches = state.range(1) == 1;
  const scallop::SurfaceDistance distance(surface, options);
  const scallop::BezierPatch& patch = surface.patches.front();
  std::mt19937_64 random(15);
  std::uniform_real_distribution<double> unit(0.05, 0.95), turn(0.0, 6.283185307179586);
  struct Query {
    scallop::Vec3 a, b;
  };
  std::vector<Query> queries(4096);
  for (Query& q : queries) {
    const double u = unit(random), v = unit(random);
    const scallop::Vec3 n = scallop::unitNormal(patch, u, v);
    const scallop::Vec3 centre = scallop::point(patch, u, v) + kToolRadius * n;
    // A direction in the tangent plane: any vector made orthogonal to n.
    const double a = turn(random);
    scallop::Vec3 t{std::cos(a), std::sin(a), 0.0};
    t = t - scallop::dot(t, n) * n;
    t = (0.025 / scallop::norm(t)) * t;
    q = {centre - t, centre + t};
  }
  std::size_t cells = 0, proven = 0;
  for (auto _ : state) {
    cells = proven = 0;
    for (const Query& q : queries) {
      const scallop::SegmentClearance result = distance.segmentClearance(q.a, q.b, kToolRadius - 1e-4);
      cells += result.cells;
      proven += result.verdict == scallop::Clearance::proven ? 1 : 0;
    }
  }
  state.counters["proven"] = static_cast<double>(proven);
  state.counters["cells_per_query"] = static_cast<double>(cells) / static_cast<double>(queries.size());
  state.counters["queries_per_s"] =
      benchmark::Counter(static_cast<double>(queries.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(fmt::format("stretched {}x, {}", state.range(0), state.range(1) == 1 ? "cut" : "whole"));
}

void BM_PatchJet(benchmark::State& state) {
  const int degree = static_cast<int>(state.range(0));
  const bool onePass = state.range(1) == 1;
  std::mt19937_64 random(16);
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0), unit(0.0, 1.0);
  scallop::BezierPatch patch{degree, degree, {}};
  for (int i = 0; i < (degree + 1) * (degree + 1); ++i)
    patch.control.push_back({coordinate(random), coordinate(random), coordinate(random)});
  std::vector<std::pair<double, double>> at(4096);
  for (auto& [u, v] : at) {
    u = unit(random);
    v = unit(random);
  }
  for (auto _ : state) {
    double sum = 0.0;
    for (const auto& [u, v] : at) {
      scallop::Vec3 r;
      scallop::PatchDerivatives d;
      if (onePass) {
        d = scallop::derivativesToSecondOrder(patch, u, v, r);
      } else {
        r = scallop::point(patch, u, v);
        d = scallop::derivativesToSecondOrder(patch, u, v);
      }
      sum += r.z + d.u.x + d.v.y + d.uu.z + d.uv.x + d.vv.y;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["evaluations_per_s"] =
      benchmark::Counter(static_cast<double>(at.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(fmt::format("bidegree ({0}, {0}), {1}", degree, onePass ? "one pass" : "point + derivatives"));
}

// A circle of radius 1 as three rational quadratic arcs of 120 degrees (middle weight
// cos 60 = 1/2), as OCCT converts one (the trimmed disk's trim); 4,096 square boxes of side
// 2^-k centred on it, moved along its normal by up to two sides either way (fixed seed).
void BM_TrimMayMeet(benchmark::State& state) {
  const int k = static_cast<int>(state.range(0));
  const bool clipping = state.range(1) == 1;
  std::vector<scallop::TrimArc> arcs;
  for (int a = 0; a < 3; ++a) {
    const double from = 2.0 * std::numbers::pi * a / 3.0, to = from + 2.0 * std::numbers::pi / 3.0;
    const double middle = 0.5 * (from + to), reach = 1.0 / std::cos(0.5 * (to - from));
    arcs.push_back({{std::cos(from), std::sin(from), 1.0},
                    {0.5 * reach * std::cos(middle), 0.5 * reach * std::sin(middle), 0.5},
                    {std::cos(to), std::sin(to), 1.0}});
  }
  std::mt19937_64 random(19);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double side = std::ldexp(1.0, -k);
  std::vector<scallop::ParameterBox> boxes(4096);
  for (scallop::ParameterBox& box : boxes) {
    const double angle = 2.0 * std::numbers::pi * unit(random), radius = 1.0 + side * (4.0 * unit(random) - 2.0);
    const double u = radius * std::cos(angle), v = radius * std::sin(angle);
    box = {u - 0.5 * side, u + 0.5 * side, v - 0.5 * side, v + 0.5 * side};
  }
  std::size_t met = 0;
  for (auto _ : state) {
    met = 0;
    for (const scallop::ParameterBox& box : boxes)
      for (const scallop::TrimArc& arc : arcs)
        met += (clipping ? scallop::mayMeet(arc, box) : scallop::detail::mayMeetByHalving(arc, box)) ? 1 : 0;
    benchmark::DoNotOptimize(met);
  }
  state.counters["boxes_per_s"] =
      benchmark::Counter(static_cast<double>(boxes.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["may_meet"] = static_cast<double>(met);
  state.SetLabel(fmt::format("side 2^-{}, {}", k, clipping ? "clipping" : "halving alone"));
}

BENCHMARK(BM_PatchJet)->ArgsProduct({{3, 5, 10, 20}, {0, 1}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TrimMayMeet)->ArgsProduct({{6, 12, 18}, {0, 1}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ClearanceLongPatch)->ArgsProduct({{1, 10, 100}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DistanceManyPatches)->Arg(1)->Arg(16)->Arg(256)->Arg(4096)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DropCutter)->Args({1, 1})->Args({1, 0})->Args({2, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LinkContour)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LinkRaster)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlanContour)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlanRaster)->Args({1, 1})->Args({2, 1})->Args({1, 0})->Args({2, 0})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DropEnvelope)->Args({1, 0})->Args({2, 0})->Args({1, 1})->Args({2, 1})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlaneSection)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);
