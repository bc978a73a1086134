#include "scallop/paths/rest_finishing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include <fmt/format.h>

#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/paths/gouge.hpp"

namespace scallop {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void validate(const RestOptions& options) {
  const auto positive = [](double value, const char* name) {
    if (!(value > 0.0) || !std::isfinite(value))
      throw Error(fmt::format("rest finishing: {} must be positive and finite, got {}", name, value));
  };
  positive(options.toolRadius, "the tool radius");
  positive(options.scallopHeight, "the scallop height");
  if (!(options.chainGap >= 0.0) || !std::isfinite(options.chainGap))
    throw Error(fmt::format("rest finishing: the chain gap must be >= 0 and finite, got {}", options.chainGap));
  if (!(options.depthTolerance >= 0.0) || !std::isfinite(options.depthTolerance))
    throw Error(fmt::format("rest finishing: the depth tolerance must be >= 0 and finite, got {}",
                            options.depthTolerance));
  if (!(options.sagTolerance >= 0.0) || !std::isfinite(options.sagTolerance))
    throw Error(fmt::format("rest finishing: the sag tolerance must be >= 0 and finite, got {}",
                            options.sagTolerance));
}

// Witnesses in square buckets of side `gap` over xy: the nearest unvisited witness within
// `gap` of a point lies in its own bucket or one of the eight around it.
class WitnessBuckets {
 public:
  WitnessBuckets(const std::vector<Vec3>& points, double gap) : points_(points), gap_(gap) {
    for (std::size_t k = 0; k < points.size(); ++k) buckets_[key(points[k])].push_back(k);
  }

  // The nearest unvisited witness to p within the gap (ties: the smaller index), removed;
  // none: points.size().
  std::size_t takeNearest(const Vec3& p) {
    const auto [bx, by] = cell(p);
    std::size_t best = points_.size();
    double bestDistance = gap_;
    for (std::int64_t dy = -1; dy <= 1; ++dy) {
      for (std::int64_t dx = -1; dx <= 1; ++dx) {
        const auto found = buckets_.find(pack(bx + dx, by + dy));
        if (found == buckets_.end()) continue;
        for (const std::size_t k : found->second) {
          const double d = norm(points_[k] - p);
          if (d < bestDistance || (d == bestDistance && k < best)) {
            bestDistance = d;
            best = k;
          }
        }
      }
    }
    if (best < points_.size()) take(best);
    return best;
  }

  void take(std::size_t k) {
    std::vector<std::size_t>& bucket = buckets_[key(points_[k])];
    bucket.erase(std::find(bucket.begin(), bucket.end(), k));
  }

 private:
  std::pair<std::int64_t, std::int64_t> cell(const Vec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x / gap_)), static_cast<std::int64_t>(std::floor(p.y / gap_))};
  }
  static std::uint64_t pack(std::int64_t x, std::int64_t y) {
    return (static_cast<std::uint64_t>(x) << 32) ^ (static_cast<std::uint64_t>(y) & 0xffffffffULL);
  }
  std::uint64_t key(const Vec3& p) const {
    const auto [x, y] = cell(p);
    return pack(x, y);
  }

  const std::vector<Vec3>& points_;
  double gap_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> buckets_;
};

// The witnesses chained nearest-next into passes (see the contract's Passes), unlifted.
ToolPath chainWitnesses(const std::vector<Vec3>& witnesses, double gap, Units units, double radius) {
  WitnessBuckets buckets(witnesses, gap);
  std::vector<bool> visited(witnesses.size(), false);
  ToolPath chains;
  chains.units = units;
  chains.toolRadius = radius;
  for (std::size_t first = 0; first < witnesses.size(); ++first) {
    if (visited[first]) continue;
    visited[first] = true;
    buckets.take(first);
    ToolPass pass;
    pass.start = witnesses[first];
    pass.retractBefore = true;
    Vec3 at = pass.start;
    for (std::size_t next = buckets.takeNearest(at); next < witnesses.size(); next = buckets.takeNearest(at)) {
      visited[next] = true;
      at = witnesses[next];
      pass.moves.push_back(ToolMove{MoveKind::line, at, {}, ArcPlane::xy, true});
    }
    if (pass.moves.empty()) pass.moves.push_back(ToolMove{MoveKind::line, at, {}, ArcPlane::xy, true});
    chains.passes.push_back(std::move(pass));
  }
  return chains;
}

double scallopAt(const SimulationReport& simulated, std::size_t index) {
  const double design = simulated.design.z[index];
  if (design == -kInf) return 0.0;
  if (!simulated.unreachable.empty() && simulated.unreachable[index]) return 0.0;
  return std::max(0.0, simulated.stock.z[index] - design) * simulated.designNormalZ[index];
}

}  // namespace

std::vector<std::size_t> restTargets(const SimulationReport& simulated, double scallopHeight,
                                     double threshold, std::size_t neighbourhood) {
  const HeightGrid& design = simulated.design;
  if (design.z.empty() || design.z.size() != design.columns * design.rows ||
      design.z.size() != simulated.stock.z.size() || simulated.designNormalZ.size() != design.z.size() ||
      (!simulated.unreachable.empty() && simulated.unreachable.size() != design.z.size()))
    throw Error("rest finishing: the simulation has no grids to read the scallops from");
  if (!(scallopHeight > 0.0) || !std::isfinite(scallopHeight))
    throw Error(fmt::format("rest finishing: the scallop height must be positive and finite, got {}", scallopHeight));
  if (!(threshold >= 0.0 && threshold <= 1.0))
    throw Error(fmt::format("rest finishing: the threshold must lie in (0, 1] (0: from the grid), got {}", threshold));
  const double cut = scallopHeight * (threshold > 0.0 ? threshold
                                                      : std::max(0.5, 1.0 - simulated.heightErrorBound / scallopHeight));
  // The squares about the points above H or beyond reach, marked one by one.
  std::vector<unsigned char> near(design.z.size(), 0);
  const auto reach = static_cast<std::ptrdiff_t>(std::min<std::size_t>(neighbourhood, 1u << 20));
  const auto columns = static_cast<std::ptrdiff_t>(design.columns);
  const auto rows = static_cast<std::ptrdiff_t>(design.rows);
  const auto mark = [&](std::ptrdiff_t i, std::ptrdiff_t j) {
    for (std::ptrdiff_t jj = std::max<std::ptrdiff_t>(0, j - reach); jj <= std::min(rows - 1, j + reach); ++jj)
      for (std::ptrdiff_t ii = std::max<std::ptrdiff_t>(0, i - reach); ii <= std::min(columns - 1, i + reach); ++ii)
        near[static_cast<std::size_t>(jj * columns + ii)] = 1;
  };
  for (std::ptrdiff_t j = 0; j < rows; ++j) {
    for (std::ptrdiff_t i = 0; i < columns; ++i) {
      const auto index = static_cast<std::size_t>(j * columns + i);
      const bool beyondReach = !simulated.unreachable.empty() && simulated.unreachable[index];
      if (beyondReach || scallopAt(simulated, index) > scallopHeight) mark(i, j);
    }
  }
  std::vector<std::size_t> targets;
  for (std::size_t index = 0; index < design.z.size(); ++index)
    if (near[index] && scallopAt(simulated, index) > cut) targets.push_back(index);
  return targets;
}

namespace {

// The targets of `simulated` (validated options), with the report's first figures in `out`:
// the path's units and radius, the targets, the largest scallop among them, the budget. Empty
// when there is nothing to do: no target, or more than the budget.
std::vector<std::size_t> startRest(const SimulationReport& simulated, const RestOptions& options, Units units,
                                   RestPasses& out) {
  validate(options);
  std::vector<std::size_t> targets =
      restTargets(simulated, options.scallopHeight, options.threshold, options.neighbourhood);
  out.path.units = units;
  out.path.toolRadius = options.toolRadius;
  for (const std::size_t index : targets)
    out.report.maxScallopBefore = std::max(out.report.maxScallopBefore, scallopAt(simulated, index));
  out.report.targets = targets.size();
  if (targets.size() > options.maxTargets) {
    out.report.overBudget = true;
    targets.clear();
  }
  return targets;
}

}  // namespace

RestPasses restPasses(const Surface& surface, const SimulationReport& simulated, const RestOptions& options) {
  RestPasses out;
  const std::vector<std::size_t> targets = startRest(simulated, options, surface.units, out);
  if (targets.empty()) return out;
  const HeightGrid& design = simulated.design;
  const double radius = options.toolRadius;
  const double height = options.scallopHeight;
  RestReport& report = out.report;

  // Their witnesses: the ball touching q, dropped onto the envelope.
  const SurfaceDistance distance(surface);
  EnvelopeOptions lifting;
  lifting.depthTolerance = options.depthTolerance;
  lifting.sagTolerance = options.sagTolerance;
  lifting.stretchThreshold = height;
  lifting.threads = options.threads;
  DropCutter cutter(distance, radius, lifting);
  std::vector<Vec3> witnesses;
  for (const std::size_t index : targets) {
    checkCancelled();
    const Vec2 p = design.point(index % design.columns, index / design.columns);
    const Vec3 q{p.x, p.y, design.z[index]};
    const ReachWitness witness = reachWitness(distance, cutter, q, radius);
    // No centre: nothing within R of the vertical, the ball cannot touch q from there.
    if (!witness.centre || witness.gap > height) {
      ++report.unreached;
      continue;
    }
    witnesses.push_back(*witness.centre);
  }
  report.witnesses = witnesses.size();
  if (witnesses.empty()) return out;

  // Chains, nearest next.
  const double gap = options.chainGap > 0.0 ? options.chainGap : std::min(8.0 * design.spacing, radius);
  const ToolPath chains = chainWitnesses(witnesses, gap, surface.units, radius);
  report.passes = chains.passes.size();

  out.path = liftToDropEnvelope(distance, chains, lifting, report.envelope);
  for (const ToolPass& pass : out.path.passes) {
    Vec3 at = pass.start;
    for (const ToolMove& move : pass.moves) {
      report.length += norm(move.end - at);
      at = move.end;
    }
  }
  return out;
}

RestPasses meshRestPasses(const Mesh& mesh, const MeshDropCutter& cutter, const SimulationReport& simulated,
                          const RestOptions& options, const DropLineOptions& dropLine) {
  RestPasses out;
  const std::vector<std::size_t> targets = startRest(simulated, options, mesh.units, out);
  if (targets.empty()) return out;
  const HeightGrid& design = simulated.design;
  const double radius = cutter.radius();
  const double height = options.scallopHeight;
  RestReport& report = out.report;
  // Witnesses: the ball touching q from q + R' n, raised onto the exact drop envelope.
  const std::vector<std::uint32_t> triangles = designTriangles(mesh, design);
  std::vector<Vec3> witnesses;
  for (const std::size_t index : targets) {
    const std::uint32_t t = triangles[index];
    if (t == kNoDesignTriangle) {
      ++report.unreached;
      continue;
    }
    const Vec2 p = design.point(index % design.columns, index / design.columns);
    const Vec3 q{p.x, p.y, design.z[index]};
    Vec3 n = triangleNormal(mesh, t);
    if (n.z < 0.0) n = -n;
    const Vec3 c = q + radius * n;
    const double z = cutter.drop(c.x, c.y).z;
    if (!std::isfinite(z)) {
      ++report.unreached;
      continue;
    }
    const double lift = std::max(0.0, z - c.z);
    if (reachGap(radius, lift, n.z) > height) {
      ++report.unreached;
      continue;
    }
    witnesses.push_back({c.x, c.y, c.z + lift});
  }
  report.witnesses = witnesses.size();
  if (witnesses.empty()) return out;
  const double gap = options.chainGap > 0.0 ? options.chainGap : std::min(8.0 * design.spacing, radius);
  const ToolPath chains = chainWitnesses(witnesses, gap, mesh.units, options.toolRadius);
  report.passes = chains.passes.size();
  // Every step an exact drop line: the ball's centre on the proven envelope between witnesses.
  for (const ToolPass& chain : chains.passes) {
    checkCancelled();
    ToolPass pass;
    pass.retractBefore = true;
    const DropLine first = cutter.dropLine({chain.start.x, chain.start.y}, {1.0, 0.0}, 0.0, 0.0, dropLine);
    pass.start = first.vertices.front().centre;
    Vec3 at = pass.start;
    for (const ToolMove& move : chain.moves) {
      const Vec2 from{at.x, at.y}, to{move.end.x, move.end.y};
      const double length = norm(to - from);
      if (length == 0.0) continue;
      const DropLine line = cutter.dropLine(from, (1.0 / length) * (to - from), 0.0, length, dropLine);
      report.envelope.proofs += line.proofs;
      report.envelope.unprovenMoves += line.unprovenMoves;
      for (std::size_t v = 1; v < line.vertices.size(); ++v) {
        pass.moves.push_back(ToolMove{MoveKind::line, line.vertices[v].centre, {}, ArcPlane::xy, true});
        report.length += norm(line.vertices[v].centre - at);
        at = line.vertices[v].centre;
      }
    }
    if (pass.moves.empty()) pass.moves.push_back(ToolMove{MoveKind::line, at, {}, ArcPlane::xy, true});
    report.envelope.movesOut += pass.moves.size();
    out.path.passes.push_back(std::move(pass));
  }
  return out;
}

}  // namespace scallop
