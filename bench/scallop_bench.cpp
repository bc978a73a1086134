// scallop-bench: the scallop hull beside its peers, in one run and one binary, so that the
// ratios survive a noisy machine.
//   BM_ScallopHull/<n>         scallopHull on a fixed-seed random-walk chain of n vertices
//   BM_UpperHull/<n>           Andrew's monotone-chain upper hull of the same chain: the
//                              r = infinity limit, and the natural floor for a stack pass
//   BM_BruteForceEnvelope/<n>  the envelope sampled at the n vertex abscissae by taking the
//                              maximum over every vertex arc and edge offset: O(n^2), as a
//                              sampling approach without the hull's ordering would

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <random>

#include "scallop/scallop_hull.hpp"

namespace {

using scallop::Chain;
using scallop::Point2;

constexpr double kRadius = 4.0;  // about four mean steps: a mix of links, lids and pops

// Random walk: x steps uniform in (0, 1], z steps standard normal; seed fixed per size.
const Chain& randomWalk(std::size_t n) {
  static std::map<std::size_t, Chain> cache;
  auto it = cache.find(n);
  if (it != cache.end()) return it->second;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> step(0.0, 1.0);
  std::normal_distribution<double> rise(0.0, 1.0);
  Chain chain;
  chain.reserve(n);
  Point2 p{0.0, 0.0};
  for (std::size_t i = 0; i < n; ++i) {
    chain.push_back(p);
    p.x += 1.0 - step(rng);  // in (0, 1]
    p.z += rise(rng);
  }
  return cache.emplace(n, std::move(chain)).first->second;
}

void BM_ScallopHull(benchmark::State& state) {
  const Chain& chain = randomWalk(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    scallop::ScallopHull result = scallop::scallopHull(chain, kRadius);
    benchmark::DoNotOptimize(result.toolpath.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

void BM_UpperHull(benchmark::State& state) {
  const Chain& chain = randomWalk(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    std::vector<std::size_t> hull = scallop::upperHullIndices(chain);
    benchmark::DoNotOptimize(hull.data());
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

double bruteForceHeight(const Chain& chain, double r, double x) {
  double best = -INFINITY;
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const Point2& v = chain[i];
    const double d = std::abs(x - v.x);
    if (d <= r) best = std::max(best, v.z + std::sqrt((r - d) * (r + d)));
    if (i + 1 == chain.size()) break;
    const Point2& w = chain[i + 1];
    const double dx = w.x - v.x;
    const double dz = w.z - v.z;
    if (dx <= 0.0) continue;
    const double len = std::hypot(dx, dz);
    const double s0 = v.x - r * dz / len;
    if (x >= s0 && x <= s0 + dx) best = std::max(best, v.z + r * dx / len + (x - s0) * dz / dx);
  }
  return best;
}

void BM_BruteForceEnvelope(benchmark::State& state) {
  const Chain& chain = randomWalk(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) {
    double sum = 0.0;
    for (const Point2& p : chain) sum += bruteForceHeight(chain, kRadius, p.x);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
}

}  // namespace

BENCHMARK(BM_ScallopHull)->RangeMultiplier(2)->Range(1 << 10, 1 << 23)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_UpperHull)->RangeMultiplier(2)->Range(1 << 10, 1 << 23)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BruteForceEnvelope)->RangeMultiplier(4)->Range(1 << 10, 1 << 14)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
