#include "paths/clearance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/paths/raster.hpp"

namespace scallop::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Box {
  double x0, x1, y0, y1, z0, z1;
};

Box controlBox(const BezierPatch& patch) {
  Box b{kInf, -kInf, kInf, -kInf, kInf, -kInf};
  for (const Vec3& p : patch.control) {
    b.x0 = std::min(b.x0, p.x), b.x1 = std::max(b.x1, p.x);
    b.y0 = std::min(b.y0, p.y), b.y1 = std::max(b.y1, p.y);
    b.z0 = std::min(b.z0, p.z), b.z1 = std::max(b.z1, p.z);
  }
  return b;
}

bool segmentsCross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  return ((d1 <= 0.0 && d2 >= 0.0) || (d1 >= 0.0 && d2 <= 0.0)) &&
         ((d3 <= 0.0 && d4 >= 0.0) || (d3 >= 0.0 && d4 <= 0.0));
}

// Horizontal distance from the segment [a, b] to the box's footprint (0 if they meet).
double segmentBoxDistance(Vec2 a, Vec2 b, const Box& box) {
  const auto inside = [&](Vec2 p) {
    return p.x >= box.x0 && p.x <= box.x1 && p.y >= box.y0 && p.y <= box.y1;
  };
  if (inside(a) || inside(b)) return 0.0;
  const Vec2 corners[4] = {{box.x0, box.y0}, {box.x1, box.y0}, {box.x1, box.y1}, {box.x0, box.y1}};
  double best = kInf;
  for (int i = 0; i < 4; ++i) {
    const Vec2 c = corners[i], d = corners[(i + 1) % 4];
    if (segmentsCross(a, b, c, d)) return 0.0;
    best = std::min({best, distanceToSegment(c, a, b), distanceToSegment(a, c, d),
                     distanceToSegment(b, c, d)});
  }
  return best;
}

}  // namespace

double HeightBound::above(Vec2 a, Vec2 b, double radius) const {
  struct Cell {
    BezierPatch patch;
    Box box;
    int depth;
  };
  const auto lower = [](const Cell& p, const Cell& q) { return p.box.z1 < q.box.z1; };
  std::priority_queue<Cell, std::vector<Cell>, decltype(lower)> queue(lower);
  // Rounding could put a box a hair too far: keep boxes up to `slack_` beyond the reach,
  // which only loosens the bound.
  const double reach = radius + slack_;
  double known = -kInf;  // the highest surface point seen in the neighbourhood
  const auto push = [&](BezierPatch&& patch, int depth) {
    const Box box = controlBox(patch);
    if (!(segmentBoxDistance(a, b, box) < reach)) return;
    const int m = patch.degreeU, n = patch.degreeV;
    for (const Vec3& c : {patch.at(0, 0), patch.at(0, n), patch.at(m, 0), patch.at(m, n),
                          point(patch, 0.5, 0.5)})
      if (distanceToSegment({c.x, c.y}, a, b) <= reach) known = std::max(known, c.z);
    queue.push({std::move(patch), box, depth});
  };
  for (const BezierPatch& patch : surface_.patches) push(BezierPatch(patch), 0);
  std::size_t cells = 0;
  while (!queue.empty()) {
    const Cell top = queue.top();
    queue.pop();
    // Every cell left lies under top.box.z1: it bounds the whole neighbourhood.
    if (top.box.z1 <= known + tolerance_ || ++cells > kLinkMaxCells || top.depth >= 40)
      return top.box.z1 + slack_;
    auto [left, right] = subdivideU(top.patch, 0.5);
    for (BezierPatch* half : {&left, &right}) {
      auto [low, high] = subdivideV(*half, 0.5);
      push(std::move(low), top.depth + 1);
      push(std::move(high), top.depth + 1);
    }
  }
  return -kInf;
}

// Proves that the ball, its centre moving along [a, b], stays at least `need` from the
// surface: sphere tracing on the distance's proven lower bound. dist(., surface) is
// 1-Lipschitz, so a centre p with dist(p) >= need + m clears every centre within m of p;
// each step advances by that margin. Gives up (false) when the margin falls below
// `minStep` (the path comes too close, or creeps along the limit) or after `maxSteps`
// (raster's pass ends: kSegmentMaxSteps).
bool segmentClears(const SurfaceDistance& distance, Vec3 a, Vec3 b, double need,
                   double reach, double minStep, int maxSteps) {
  const double length = norm(b - a);
  // A coarse look first, at steps of `reach` / 16: most failing candidates cut in visibly
  // somewhere, and one cheap query (settled by a few boxes, cutoff `need`) shows it.
  const int coarse = static_cast<int>(std::min(256.0, std::ceil(16.0 * length / reach)));
  for (int i = 1; i <= coarse; ++i) {
    if (distance.closest(a + (b - a) * (double(i) / coarse), need).distance < need) return false;
  }
  double t = 0.0;
  double stride = minStep;  // the last margin
  for (int step = 0; step < maxSteps; ++step) {
    const Vec3 p = length > 0.0 ? a + (b - a) * (t / length) : a;
    // The cutoff: a bound tighter than need + twice the last margin (or reach) is not worth
    // its cells; the margin can then double from one step to the next, no more.
    const double cutoff = need + std::min(reach, 2.0 * stride);
    const double margin = distance.closest(p, cutoff).lowerBound - need;
    if (!(margin > minStep)) return false;
    if (t + margin >= length) return true;
    t += margin;
    stride = std::max(margin, 64.0 * minStep);
  }
  return false;
}

}  // namespace scallop::detail
