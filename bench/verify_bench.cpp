// scallop-bench, the cut simulator (`scallop verify`) on the main job's programs:
//   BM_Verify/<surface>/<strategy>  read the G-code program of `scallop plan` (R = 0.25 in,
//                                   H = 0.001 in; contour on N*, or raster at the best feed
//                                   angle) and simulate it on the default grid (spacing
//                                   0.0056 in, 543 x 543 points): grid points per second
//                                   ("cells/s": the whole verification) and (move, point)
//                                   envelope evaluations per second, side by side with
//   BM_VerifyDesign/<surface>       the design heights alone (the surface seen from above).

#include <benchmark/benchmark.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "scallop/paths/contour.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/io/gcode.hpp"
#include "scallop/io/gcode_reader.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/raster.hpp"
#include "scallop/geometry/surface.hpp"

namespace {

constexpr double kToolRadius = 0.25;
constexpr double kScallopHeight = 0.001;

const char* surfaceName(std::int64_t index) { return index == 1 ? "paper-1" : "paper-2"; }

std::string planProgram(const scallop::Surface& surface, bool raster) {
  scallop::ToolPath path;
  if (raster) {
    scallop::RasterOptions options;
    options.bestAngle = true;
    options.toolRadius = kToolRadius;
    options.scallopHeight = kScallopHeight;
    path = scallop::rasterPaths(surface, options).path;
  } else {
    const scallop::OptimalSlicing orientation = scallop::optimalSlicing(surface);
    scallop::ContourOptions options;
    options.normal = orientation.normal;
    options.toolRadius = kToolRadius;
    options.spacing = scallop::spacingForScallopHeight(kToolRadius, kScallopHeight, orientation.certifiedAlphaRad);
    path = scallop::contourPaths(surface, options).path;
  }
  scallop::GcodeOptions gcode;
  gcode.safeHeight = 3.0;
  gcode.feedRate = 40.0;
  gcode.plungeFeedRate = 15.0;
  gcode.spindleRpm = 10000.0;
  return scallop::gcodeProgram(path, gcode);
}

void BM_Verify(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state.range(0)));
  const bool raster = state.range(1) == 1;
  const std::string text = planProgram(surface, raster);
  scallop::SimulationOptions options;
  options.toolRadius = kToolRadius;
  options.scallopHeight = kScallopHeight;
  std::size_t points = 0, visits = 0, moves = 0;
  double gouge = 0.0;
  for (auto _ : state) {
    const scallop::GcodeProgram program = scallop::parseGcodeProgram(text, "plan.ngc");
    const scallop::SimulationReport report = scallop::verifyProgram(surface, program, options);
    points = report.design.z.size();
    visits = report.sweptPointVisits;
    moves = report.moves;
    gouge = report.maxGouge;
    benchmark::DoNotOptimize(report.maxScallop);
  }
  state.counters["cells/s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["visits/s"] = benchmark::Counter(static_cast<double>(visits), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["moves"] = static_cast<double>(moves);
  state.counters["gouge_in"] = gouge;
  state.SetLabel(std::string(surfaceName(state.range(0))) + (raster ? " raster" : " contour"));
}

void BM_VerifyDesign(benchmark::State& state) {
  const scallop::Surface surface = scallop::exampleSurface(surfaceName(state.range(0)));
  scallop::SimulationOptions options;
  options.toolRadius = kToolRadius;
  options.scallopHeight = kScallopHeight;
  scallop::HeightGrid grid = scallop::simulationGrid(surface, options);
  for (auto _ : state) {
    scallop::designHeights(surface, grid);
    benchmark::DoNotOptimize(grid.z.data());
  }
  state.counters["cells/s"] = benchmark::Counter(static_cast<double>(grid.z.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel(surfaceName(state.range(0)));
}

}  // namespace

BENCHMARK(BM_Verify)->ArgsProduct({{1, 2}, {0, 1}})->Unit(benchmark::kMillisecond);
BENCHMARK(BM_VerifyDesign)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
