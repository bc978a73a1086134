// scallop-bench, the mesh drop-cutter (mesh_drop.hpp) on the paper's surfaces tessellated
// (each patch sampled on a 100 x 100 grid of (u, v), every cell two triangles: 20,000 per
// patch), side by side with the Bezier drop-cutter of BM_DropCutter (paths_bench.cpp) on the
// same 100 x 100 grid of points:
//   BM_MeshDrop/<surface>       drops on a 100 x 100 grid over the footprint grown by R:
//                               points per second (the index built outside the loop)
//   BM_MeshDropIndex/<surface>  building the index (MeshDropCutter's constructor)
//   BM_MeshDropLine/<surface>   drop lines (eps = sag tolerance = 1e-6 of the mesh's size) on
//                               20 raster lines along x across the footprint: vertices,
//                               proofs and unproven moves as counters

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/paths/mesh_drop.hpp"
#include "scallop/geometry/surface.hpp"

namespace {

constexpr double kMeshToolRadius = 0.25;  // inches, as the paper's Table 1
constexpr int kTessellation = 100;

const char* meshSurfaceName(const benchmark::State& state) {
  return state.range(0) == 1 ? "paper-1" : "paper-2";
}

scallop::Mesh tessellated(const std::string& name) {
  const scallop::Surface surface = scallop::exampleSurface(name);
  scallop::Mesh mesh;
  mesh.units = surface.units;
  for (const scallop::BezierPatch& patch : surface.patches) {
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    for (int j = 0; j <= kTessellation; ++j)
      for (int i = 0; i <= kTessellation; ++i)
        mesh.vertices.push_back(scallop::point(patch, double(i) / kTessellation, double(j) / kTessellation));
    const auto id = [&](int i, int j) { return base + static_cast<std::uint32_t>(j * (kTessellation + 1) + i); };
    for (int j = 0; j < kTessellation; ++j)
      for (int i = 0; i < kTessellation; ++i) {
        mesh.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        mesh.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
  }
  return mesh;
}

struct Footprint {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
};

Footprint footprint(const scallop::Mesh& mesh, double grow) {
  Footprint f;
  for (const scallop::Vec3& p : mesh.vertices) {
    f.x0 = std::min(f.x0, p.x - grow);
    f.x1 = std::max(f.x1, p.x + grow);
    f.y0 = std::min(f.y0, p.y - grow);
    f.y1 = std::max(f.y1, p.y + grow);
  }
  return f;
}

void BM_MeshDrop(benchmark::State& state) {
  const scallop::Mesh mesh = tessellated(meshSurfaceName(state));
  const scallop::MeshDropCutter cutter(mesh, kMeshToolRadius);
  const Footprint f = footprint(mesh, kMeshToolRadius);
  constexpr int kGrid = 100;
  double sum = 0.0;
  for (auto _ : state) {
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i) {
        const double x = f.x0 + (f.x1 - f.x0) * (i + 0.5) / kGrid;
        const double y = f.y0 + (f.y1 - f.y0) * (j + 0.5) / kGrid;
        sum += std::max(cutter.drop(x, y).z, 0.0);
      }
  }
  benchmark::DoNotOptimize(sum);
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(kGrid * kGrid), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["triangles"] = static_cast<double>(mesh.triangles.size());
  state.SetLabel(meshSurfaceName(state));
}

void BM_MeshDropIndex(benchmark::State& state) {
  const scallop::Mesh mesh = tessellated(meshSurfaceName(state));
  for (auto _ : state) {
    const scallop::MeshDropCutter cutter(mesh, kMeshToolRadius);
    benchmark::DoNotOptimize(cutter.cellSize());
  }
  state.SetLabel(meshSurfaceName(state));
}

void BM_MeshDropLine(benchmark::State& state) {
  const scallop::Mesh mesh = tessellated(meshSurfaceName(state));
  const scallop::MeshDropCutter cutter(mesh, kMeshToolRadius);
  const Footprint f = footprint(mesh, kMeshToolRadius);
  constexpr int kLines = 20;
  std::size_t vertices = 0, proofs = 0, unproven = 0;
  for (auto _ : state) {
    vertices = proofs = unproven = 0;
    for (int j = 0; j < kLines; ++j) {
      const double y = f.y0 + (f.y1 - f.y0) * (j + 0.5) / kLines;
      const scallop::DropLine line = cutter.dropLine({f.x0, y}, {1.0, 0.0}, 0.0, f.x1 - f.x0);
      vertices += line.vertices.size();
      proofs += line.proofs;
      unproven += line.unprovenMoves;
    }
  }
  state.counters["vertices"] = static_cast<double>(vertices);
  state.counters["proofs"] = static_cast<double>(proofs);
  state.counters["unproven"] = static_cast<double>(unproven);
  state.SetLabel(meshSurfaceName(state));
}

}  // namespace

BENCHMARK(BM_MeshDrop)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeshDropIndex)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MeshDropLine)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
