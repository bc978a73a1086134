// Rest finishing (rest_finishing.hpp): the targets against a brute-force reading of the
// contract on random grids, and the rest passes judged by the simulated cut (cut_simulation.hpp,
// which knows nothing of how they were made) and the independent distance reference.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "support/distance_reference.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/paths/cut_simulation.hpp"
#include "scallop/error.hpp"
#include "scallop/slicing/optimal_slicing.hpp"
#include "scallop/paths/rest_finishing.hpp"
#include "scallop/geometry/surface.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A simulation report with only the fields restTargets reads: flat design at z = 0 (or no
// surface), |n_z| per point, stock = design + scallop / |n_z|.
struct Field {
  std::size_t columns = 0, rows = 0;
  std::vector<double> scallop;          // what the grid reads; < 0: no surface
  std::vector<unsigned char> beyond;    // beyond the ball's reach
  std::vector<double> normalZ;
};

SimulationReport reportOf(const Field& field, double heightErrorBound) {
  SimulationReport report;
  report.heightErrorBound = heightErrorBound;
  for (HeightGrid* grid : {&report.design, &report.stock}) {
    grid->spacing = 0.01;
    grid->columns = field.columns;
    grid->rows = field.rows;
    grid->z.assign(field.columns * field.rows, 0.0);
  }
  report.designNormalZ.assign(field.columns * field.rows, 0.0);
  report.unreachable = field.beyond;
  for (std::size_t k = 0; k < field.scallop.size(); ++k) {
    if (field.scallop[k] < 0.0) {
      report.design.z[k] = -kInf;
      report.stock.z[k] = 1.0;
      continue;
    }
    report.designNormalZ[k] = field.normalZ[k];
    report.stock.z[k] = field.scallop[k] / field.normalZ[k];
  }
  return report;
}

// The contract's Targets read literally: O(P^2).
std::vector<std::size_t> bruteForceTargets(const Field& field, double height, double cut, std::size_t reach) {
  const auto seed = [&](std::size_t k) { return field.beyond[k] || (field.scallop[k] >= 0.0 && field.scallop[k] > height); };
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < field.scallop.size(); ++k) {
    if (field.scallop[k] < 0.0 || field.beyond[k] || !(field.scallop[k] > cut)) continue;
    const std::size_t i = k % field.columns, j = k / field.columns;
    bool near = false;
    for (std::size_t other = 0; other < field.scallop.size() && !near; ++other) {
      const std::size_t a = other % field.columns, b = other / field.columns;
      const std::size_t di = a > i ? a - i : i - a, dj = b > j ? b - j : j - b;
      near = std::max(di, dj) <= reach && seed(other);
    }
    if (near) out.push_back(k);
  }
  return out;
}

TEST(RestTargets, AgreeWithTheContractReadByBruteForceOnRandomGrids) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double height = 0.001;
  std::size_t cases = 0, nonEmpty = 0;
  for (int trial = 0; trial < 600; ++trial) {
    Field field;
    field.columns = 1 + rng() % 24;
    field.rows = 1 + rng() % 24;
    const std::size_t n = field.columns * field.rows;
    field.scallop.resize(n);
    field.beyond.assign(n, 0);
    field.normalZ.resize(n);
    const double holes = unit(rng) * 0.3, above = unit(rng) * 0.05, beyond = unit(rng) * 0.03;
    for (std::size_t k = 0; k < n; ++k) {
      field.normalZ[k] = 0.2 + 0.8 * unit(rng);
      if (unit(rng) < holes) {
        field.scallop[k] = -1.0;
        continue;
      }
      // Mostly below H, a few above; some exactly at the cuts (ties are not above).
      const double r = unit(rng);
      field.scallop[k] = r < above ? height * (1.0 + unit(rng)) : height * unit(rng);
      if (unit(rng) < 0.02) field.scallop[k] = height;
      if (unit(rng) < beyond) field.beyond[k] = 1;
    }
    const double bound = height * 0.5 * unit(rng);
    const std::size_t reach = rng() % 6;
    const double threshold = trial % 3 == 0 ? 0.0 : 0.5 + 0.5 * unit(rng);
    // The stock is rebuilt from scallop / |n_z| and read back as (stock - design) |n_z|:
    // rounding may move a value across a cut, so the reference reads the same numbers.
    const SimulationReport report = reportOf(field, bound);
    for (std::size_t k = 0; k < n; ++k)
      if (field.scallop[k] >= 0.0) field.scallop[k] = report.stock.z[k] * report.designNormalZ[k];
    const double cut = height * (threshold > 0.0 ? threshold : std::max(0.5, 1.0 - bound / height));
    const std::vector<std::size_t> expected = bruteForceTargets(field, height, cut, reach);
    EXPECT_EQ(restTargets(report, height, threshold, reach), expected) << "trial " << trial;
    ++cases;
    if (!expected.empty()) ++nonEmpty;
  }
  EXPECT_EQ(cases, 600u);
  EXPECT_GT(nonEmpty, 200u);  // the cases exercise the selection, not only empty answers
}

TEST(RestTargets, NothingAboveHAndNothingBeyondReachMeansNothingToDo) {
  Field field;
  field.columns = field.rows = 10;
  field.scallop.assign(100, 0.00099);  // just below H everywhere
  field.beyond.assign(100, 0);
  field.normalZ.assign(100, 1.0);
  EXPECT_TRUE(restTargets(reportOf(field, 0.00025), 0.001).empty());
  field.scallop[55] = 0.0011;  // one point above: it and its neighbours above 0.75 H
  EXPECT_EQ(restTargets(reportOf(field, 0.00025), 0.001).size(), 100u);
  EXPECT_EQ(restTargets(reportOf(field, 0.00025), 0.001, 0.0, 0).size(), 1u);
  EXPECT_EQ(restTargets(reportOf(field, 0.00025), 0.001, 0.995, 3).size(), 1u);
}

TEST(RestTargets, RejectsBadInput) {
  Field field;
  field.columns = field.rows = 3;
  field.scallop.assign(9, 0.0);
  field.beyond.assign(9, 0);
  field.normalZ.assign(9, 1.0);
  const SimulationReport report = reportOf(field, 0.0);
  EXPECT_THROW(restTargets(report, 0.0), Error);
  EXPECT_THROW(restTargets(report, std::nan("")), Error);
  EXPECT_THROW(restTargets(report, 0.001, 1.5), Error);
  EXPECT_THROW(restTargets(report, 0.001, -0.1), Error);
  EXPECT_THROW(restTargets(SimulationReport{}, 0.001), Error);
  SimulationReport broken = report;
  broken.stock.z.pop_back();
  EXPECT_THROW(restTargets(broken, 0.001), Error);
}

// paper-1, contour on N* with a 0.25 in ball and the flat spacing for H = 0.001 in, two
// passes left out: strips of material up to several H. The rest passes must finish every
// target to H (the simulated cut of the path with them), touch nothing deeper than eps (the
// independent distance reference), and come out the same twice.
TEST(RestPasses, FinishTheStripsAPathLeftAndCutNothing) {
  const Surface surface = exampleSurface("paper-1");
  const double radius = 0.25, height = 0.001;
  const OptimalSlicing orientation = optimalSlicing(surface);
  ContourOptions contour;
  contour.normal = orientation.normal.z < 0.0 ? -orientation.normal : orientation.normal;
  contour.toolRadius = radius;
  contour.spacing = spacingForScallopHeight(radius, height, orientation.certifiedAlphaRad);
  const ContourPaths paths = contourPaths(surface, contour);
  ToolPath gappy = paths.path;
  gappy.passes.clear();
  for (std::size_t k = 0; k < paths.path.passes.size(); ++k)
    if (k != paths.path.passes.size() / 2 && k != paths.path.passes.size() / 4) gappy.passes.push_back(paths.path.passes[k]);

  SimulationOptions simulation;
  simulation.toolRadius = radius;
  simulation.scallopHeight = height;
  simulation.resolution = 0.02;
  const SimulationReport before = verifyToolPath(surface, gappy, simulation);
  ASSERT_GT(before.maxScallop, 3.0 * height);
  ASSERT_GT(before.uncutPoints, 100u);

  RestOptions options;
  options.toolRadius = radius;
  options.scallopHeight = height;
  options.sagTolerance = height / 4.0;
  const RestPasses rest = restPasses(surface, before, options);
  const RestReport& r = rest.report;
  const std::vector<std::size_t> targets = restTargets(before, height);
  EXPECT_EQ(r.targets, targets.size());
  EXPECT_EQ(r.targets, r.witnesses + r.unreached);
  EXPECT_EQ(r.unreached, 0u);  // paper-1 has no concave radius below 0.25 in
  EXPECT_EQ(r.passes, rest.path.passes.size());
  EXPECT_FALSE(r.overBudget);
  EXPECT_EQ(r.envelope.unprovenMoves, 0u);
  EXPECT_GT(r.maxScallopBefore, 3.0 * height);
  std::printf("[          ] %zu targets, %zu passes, %.3f in, %zu moves, %zu proofs\n", r.targets, r.passes,
              r.length, r.envelope.movesOut, r.envelope.proofs);

  // The judge: the simulated cut of the path with the rest passes.
  ToolPath finished = gappy;
  finished.passes.insert(finished.passes.end(), rest.path.passes.begin(), rest.path.passes.end());
  const SimulationReport after = verifyToolPath(surface, finished, simulation);
  double worstTarget = 0.0;
  for (const std::size_t index : targets)
    worstTarget = std::max(worstTarget, (after.stock.z[index] - after.design.z[index]) * after.designNormalZ[index]);
  std::printf("[          ] max scallop %.6f -> %.6f in; at the targets %.6f in; gouge %.3g in\n", before.maxScallop,
              after.maxScallop, worstTarget, after.maxGouge);
  EXPECT_LE(worstTarget, height);
  EXPECT_EQ(after.uncutPoints, 0u);
  EXPECT_LE(after.maxGouge, before.maxGouge + 1e-5);

  // Gouge-free by the reference: every move's ends and midpoints at least R - eps away.
  const double eps = r.envelope.depthTolerance;
  double deepest = -1.0;
  std::size_t samples = 0;
  for (const ToolPass& pass : rest.path.passes) {
    Vec3 at = pass.start;
    for (const ToolMove& move : pass.moves) {
      for (const double t : {0.0, 0.5, 1.0}) {
        const Vec3 p = at + t * (move.end - at);
        deepest = std::max(deepest, radius - reference::referenceDistance(surface, p, 20, 3).refined);
        ++samples;
      }
      at = move.end;
    }
  }
  std::printf("[          ] %zu samples, deepest %.3g in (eps %.3g)\n", samples, deepest, eps);
  EXPECT_GT(samples, 0u);
  EXPECT_LE(deepest, eps + 1e-12);

  // Deterministic.
  const RestPasses again = restPasses(surface, before, options);
  ASSERT_EQ(again.path.passes.size(), rest.path.passes.size());
  for (std::size_t k = 0; k < rest.path.passes.size(); ++k) {
    ASSERT_EQ(again.path.passes[k].moves.size(), rest.path.passes[k].moves.size());
    EXPECT_EQ(again.path.passes[k].start, rest.path.passes[k].start);
    for (std::size_t m = 0; m < rest.path.passes[k].moves.size(); ++m)
      EXPECT_EQ(again.path.passes[k].moves[m].end, rest.path.passes[k].moves[m].end);
  }

  // Over the budget: nothing made, and said.
  RestOptions tight = options;
  tight.maxTargets = r.targets - 1;
  const RestPasses none = restPasses(surface, before, tight);
  EXPECT_TRUE(none.report.overBudget);
  EXPECT_TRUE(none.path.passes.empty());
  EXPECT_EQ(none.report.targets, r.targets);
}

TEST(RestPasses, RejectsBadOptions) {
  const Surface surface = exampleSurface("paper-1");
  SimulationOptions simulation;
  simulation.toolRadius = 0.25;
  simulation.scallopHeight = 0.001;
  simulation.resolution = 0.1;
  const SimulationReport report = verifyToolPath(surface, ToolPath{Units::inch, 0.25, {}}, simulation);
  RestOptions good;
  good.toolRadius = 0.25;
  good.scallopHeight = 0.001;
  for (const auto& change : std::vector<void (*)(RestOptions&)>{
           [](RestOptions& o) { o.toolRadius = 0.0; },
           [](RestOptions& o) { o.scallopHeight = -1.0; },
           [](RestOptions& o) { o.threshold = 2.0; },
           [](RestOptions& o) { o.chainGap = -1.0; },
           [](RestOptions& o) { o.depthTolerance = std::nan(""); },
           [](RestOptions& o) { o.sagTolerance = kInf; },
       }) {
    RestOptions bad = good;
    change(bad);
    EXPECT_THROW(restPasses(surface, report, bad), Error);
  }
  // Uncut stock everywhere is over the budget (the whole surface), not a plan to make.
  good.maxTargets = 10;
  const RestPasses none = restPasses(surface, report, good);
  EXPECT_TRUE(none.path.passes.empty());
}

}  // namespace
}  // namespace scallop
