#include <gtest/gtest.h>
#include <cstdio>
#include <random>
#include <numbers>
#include <map>
#include "scallop/error.hpp"
#include "scallop/medial_axis.hpp"
using namespace scallop;
static std::vector<Vec2> star(std::mt19937_64& rng, Vec2 c, int n, double r0, double r1) {
  std::uniform_real_distribution<double> ang(0, 2 * std::numbers::pi), rad(r0, r1);
  std::vector<double> a(n); for (auto& x : a) x = ang(rng); std::sort(a.begin(), a.end());
  std::vector<Vec2> l; for (double x : a) { double r = rad(rng); l.push_back({c.x + r * std::cos(x), c.y + r * std::sin(x)}); } return l;
}
// Random orthogonal "staircase" star: integer coordinates on a small grid.
static std::vector<Vec2> orthoStar(std::mt19937_64& rng, int n, int scale) {
  std::uniform_int_distribution<int> rad(scale / 3, scale);
  std::vector<Vec2> l;
  // walk angles in 4 quadrants with axis-aligned steps: build from a star, then snap to staircase
  auto s = star(rng, {0, 0}, n, 0.3, 1.0);
  for (size_t i = 0; i < s.size(); ++i) {
    Vec2 p{std::round(s[i].x * scale), std::round(s[i].y * scale)};
    Vec2 q{std::round(s[(i + 1) % s.size()].x * scale), std::round(s[(i + 1) % s.size()].y * scale)};
    l.push_back(p); l.push_back({q.x, p.y});
  }
  return l;
}
TEST(MedialAxisStress, Random) {
  std::mt19937_64 rng(7);
  std::map<std::string, int> errors; int rebuilds = 0, runs = 0, maxReb = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    PlanarDomain d;
    MedialAxisOptions o;
    int kind = trial % 3;
    if (kind == 0) { d.loops.push_back(star(rng, {0, 0}, 3 + trial % 200, 0.2, 1.0)); }
    if (kind == 1) { d.loops.push_back(star(rng, {0, 0}, 50, 0.8, 1.0)); d.loops.push_back(star(rng, {0.1, 0}, 3 + trial % 20, 0.1, 0.4)); o.rotationRad = 0.001 * trial; }
    if (kind == 2) { d.loops.push_back(orthoStar(rng, 5 + trial % 40, 20 + trial % 1000)); o.gridStep = 1; }
    try {
      auto ma = medialAxis(d, o); ++runs; rebuilds += ma.rebuilds; maxReb = std::max(maxReb, ma.rebuilds);
      if (ma.rebuilds) std::printf("trial %d kind %d rebuilds %d\n", trial, kind, ma.rebuilds);
      auto c = checkMedialAxis(d, ma, 5); if (!c.ok) std::printf("trial %d check FAILED %s\n", trial, c.firstFailure.c_str());
    } catch (const Error& e) { std::string w = e.what(); errors[w.substr(0, 60)]++; if (w.find("validation") != std::string::npos) std::printf("trial %d kind %d: %s\n", trial, kind, e.what()); }
  }
  std::printf("runs %d rebuilds %d max %d\n", runs, rebuilds, maxReb);
  for (auto& [k, v] : errors) std::printf("  %d x %s\n", v, k.c_str());
}
