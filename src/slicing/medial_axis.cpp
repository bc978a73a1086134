// Medial axis transform of a polygonal domain from Boost.Polygon's Voronoi diagram of its
// integer-scaled boundary segments. See include/scallop/medial_axis.hpp for the contract,
// the integer scaling, the tolerance and the validation/rebuild scheme.
//
// Layout of this file:
//   geometry helpers and a bounding-volume hierarchy (BVH) over segments;
//   DomainIndex: the input domain in the caller's frame, for clearances and inside tests
//     (independent of Boost: the validator);
//   GridDomain: the rotated, integer-scaled, cleaned, checked and re-oriented domain;
//   EdgeRecorder: the output structure fed by boost::polygon::voronoi_builder;
//   extraction of the interior edges with their Bezier control points and radius data;
//   the build / validate / rotate-and-rebuild loop.

#include "scallop/slicing/medial_axis.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <boost/polygon/voronoi_builder.hpp>
#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {
namespace {

// Grid half-range: the larger half-side of the (rotated) bounding box maps to 2^29 steps.
// With |coordinates| <= 2^29, differences are <= 2^30, products <= 2^60 and a 2x2
// determinant <= 2^61: every orientation test below is exact in int64.
constexpr double kGridHalfRange = 536870912.0;  // 2^29
constexpr std::int64_t kGridLimit = std::int64_t{1} << 29;
// Further rotation per rebuild: incommensurable with pi/2.
constexpr double kRebuildStep = std::numbers::sqrt2 - 1.0;
// Edges shorter than this (grid steps) carry no geometry beyond the tolerance: dropped.
constexpr double kShortEdge = 1e-3;
// A side test within this (grid steps) of zero is undecided. Boost's vertex coordinates
// are computed to a fixed relative precision (its own diagram treats vertices within 128
// ulps as one: ~1.5e-5 steps at 2^29), so genuine interior points are far beyond it.
constexpr double kSideEps = 1e-3;
// The sample of checkMedialAxis may be this many tolerances from the boundary before the
// search gives up (the clearance is then known to exceed the radius by too much).
constexpr double kSearchSlack = 4.0;

double sq(double v) { return v * v; }

Vec2 unit(Vec2 v) {
  const double n = norm(v);
  return {v.x / n, v.y / n};
}

Vec2 lerp(Vec2 a, Vec2 b, double t) { return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t}; }

// Squared distance from p to the segment a-b, and the parameter of the nearest point
// (exactly 0 or 1 when that point is an end).
double distance2ToSegment(Vec2 p, Vec2 a, Vec2 b, double* tOut) {
  const Vec2 d = b - a;
  const double len2 = dot(d, d);
  double t = 0.0;
  if (len2 > 0.0) {
    t = dot(p - a, d) / len2;
    t = std::clamp(t, 0.0, 1.0);
  }
  if (tOut != nullptr) *tOut = t;
  const Vec2 foot = t == 1.0 ? b : a + d * t;
  const Vec2 e = p - foot;
  return dot(e, e);
}

// Which side of the boundary x lies on, seen from a vertex p whose loop runs
// prev -> p -> next with the domain on its left: > 0 inside, < 0 outside, in units of
// |x - p| times a sine. Convex vertex: inside both edges' half-planes; reflex: either.
double wedgeSide(Vec2 prev, Vec2 p, Vec2 next, Vec2 x) {
  const Vec2 uIn = unit(p - prev);
  const Vec2 uOut = unit(next - p);
  const Vec2 d = x - p;
  const double cIn = cross(uIn, d);
  const double cOut = cross(uOut, d);
  const double turn = cross(uIn, uOut);
  if (turn > 0.0) return std::min(cIn, cOut);
  if (turn < 0.0) return std::max(cIn, cOut);
  return cOut;
}

// ---------------------------------------------------------------------------------------
// Bounding-volume hierarchy over segments given loop by loop: nearest-segment queries in
// O(log n) on average, and box queries. Nodes are index ranges split in the middle, so a
// node within one loop is a contiguous chain, bounded by its box and by the capsule around
// its chord (radius: the chain's largest deviation from the chord). The capsule matters: a
// medial-axis disc touches a curved boundary tangentially, and a box is loose by half the
// chain's length there while the capsule is loose by its sagitta (quadratic in the length);
// on a 50,000-gon boxes alone cost ~250 segment tests per query. (A uniform grid, the
// usual alternative, holds ~sqrt(n) segments per occupied cell of an n-cell grid when the
// segments lie along curves.)

struct Box {
  double x0 = std::numeric_limits<double>::infinity();
  double y0 = std::numeric_limits<double>::infinity();
  double x1 = -std::numeric_limits<double>::infinity();
  double y1 = -std::numeric_limits<double>::infinity();
  void add(Vec2 p) {
    x0 = std::min(x0, p.x);
    y0 = std::min(y0, p.y);
    x1 = std::max(x1, p.x);
    y1 = std::max(y1, p.y);
  }
  bool overlaps(const Box& b) const {
    return x0 <= b.x1 && b.x0 <= x1 && y0 <= b.y1 && b.y0 <= y1;
  }
  double distance2(Vec2 p) const {
    const double dx = std::max({x0 - p.x, 0.0, p.x - x1});
    const double dy = std::max({y0 - p.y, 0.0, p.y - y1});
    return dx * dx + dy * dy;
  }
};

class SegmentTree {
 public:
  struct Hit {
    bool found = false;
    std::uint32_t segment = 0;
    double distance2 = 0.0;
    double t = 0.0;
  };

  SegmentTree() = default;
  // Segment i runs from a[i] to b[i]; consecutive segments of a loop should be consecutive
  // (b[i] == a[i + 1]) for the capsule bounds to apply.
  SegmentTree(std::vector<Vec2> a, std::vector<Vec2> b) : a_(std::move(a)), b_(std::move(b)) {
    if (!a_.empty()) {
      nodes_.reserve(2 * a_.size() / kLeafSize + 2);
      build(0, static_cast<std::uint32_t>(a_.size()));
    }
  }

  // The nearest segment to p closer than sqrt(maxDistance2) (found = false if none).
  Hit nearest(Vec2 p, double maxDistance2) const {
    Hit best;
    best.distance2 = maxDistance2;
    if (nodes_.empty()) return best;
    std::array<std::pair<std::uint32_t, double>, kStackSize> stack;
    std::size_t top = 0;
    stack[top++] = {0, lowerBound2(nodes_[0], p)};
    while (top > 0) {
      const auto [index, bound2] = stack[--top];
      if (bound2 >= best.distance2) continue;
      const Node& node = nodes_[index];
      if (node.left < 0) {
        for (std::uint32_t s = node.begin; s < node.end; ++s) {
          double t = 0.0;
          const double d2 = distance2ToSegment(p, a_[s], b_[s], &t);
          if (d2 < best.distance2) best = {true, s, d2, t};
        }
        continue;
      }
      const auto left = static_cast<std::uint32_t>(node.left);
      const auto right = static_cast<std::uint32_t>(node.right);
      const double dl = lowerBound2(nodes_[left], p);
      const double dr = lowerBound2(nodes_[right], p);
      // Push the farther child first so that the nearer one is explored first.
      if (dl <= dr) {
        if (dr < best.distance2) stack[top++] = {right, dr};
        if (dl < best.distance2) stack[top++] = {left, dl};
      } else {
        if (dl < best.distance2) stack[top++] = {left, dl};
        if (dr < best.distance2) stack[top++] = {right, dr};
      }
    }
    return best;
  }

  // Calls f(segment) for every segment whose bounding box overlaps `box`.
  template <class F>
  void forEachOverlapping(const Box& box, F&& f) const {
    if (nodes_.empty()) return;
    std::array<std::uint32_t, kStackSize> stack;
    std::size_t top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (!node.box.overlaps(box)) continue;
      if (node.left < 0) {
        for (std::uint32_t s = node.begin; s < node.end; ++s) {
          Box sb;
          sb.add(a_[s]);
          sb.add(b_[s]);
          if (sb.overlaps(box)) f(s);
        }
        continue;
      }
      stack[top++] = static_cast<std::uint32_t>(node.left);
      stack[top++] = static_cast<std::uint32_t>(node.right);
    }
  }

 private:
  static constexpr std::uint32_t kLeafSize = 4;
  // Halving splits: depth <= log2(n / kLeafSize) + 1 <= 31, two entries per level at most.
  static constexpr std::size_t kStackSize = 128;

  struct Node {
    Box box;
    Vec2 chordA;  // capsule: every segment of the node lies within `deviation` of the
    Vec2 chordB;  // chord chordA-chordB (infinite deviation: not a chain, box only)
    double deviation = std::numeric_limits<double>::infinity();
    std::uint32_t begin = 0;
    std::uint32_t end = 0;
    std::int32_t left = -1;  // -1: leaf
    std::int32_t right = -1;
  };

  static double lowerBound2(const Node& node, Vec2 p) {
    const double boxBound2 = node.box.distance2(p);
    if (!(node.deviation < std::numeric_limits<double>::infinity())) return boxBound2;
    const double chord2 = distance2ToSegment(p, node.chordA, node.chordB, nullptr);
    if (chord2 <= node.deviation * node.deviation) return boxBound2;
    const double capsule = std::sqrt(chord2) - node.deviation;
    return std::max(boxBound2, capsule * capsule);
  }

  std::int32_t build(std::uint32_t begin, std::uint32_t end) {
    Node node;
    node.begin = begin;
    node.end = end;
    bool chain = true;
    for (std::uint32_t s = begin; s < end; ++s) {
      node.box.add(a_[s]);
      node.box.add(b_[s]);
      if (s + 1 < end && !(b_[s] == a_[s + 1])) chain = false;
    }
    if (chain) {
      node.chordA = a_[begin];
      node.chordB = b_[end - 1];
      double deviation2 = 0.0;
      for (std::uint32_t s = begin; s < end; ++s) {
        deviation2 =
            std::max(deviation2, distance2ToSegment(b_[s], node.chordA, node.chordB, nullptr));
      }
      // Relative slack for the rounding of the two distances compared in lowerBound2.
      node.deviation = std::sqrt(deviation2) * (1.0 + 1e-12) +
                       1e-15 * (std::abs(node.box.x0) + std::abs(node.box.x1) +
                                std::abs(node.box.y0) + std::abs(node.box.y1));
    }
    const auto index = static_cast<std::int32_t>(nodes_.size());
    nodes_.push_back(node);
    if (end - begin <= kLeafSize) return index;
    const std::uint32_t mid = begin + (end - begin) / 2;
    const std::int32_t left = build(begin, mid);
    const std::int32_t right = build(mid, end);
    nodes_[static_cast<std::size_t>(index)].left = left;
    nodes_[static_cast<std::size_t>(index)].right = right;
    return index;
  }

  std::vector<Vec2> a_;
  std::vector<Vec2> b_;
  std::vector<Node> nodes_;
};

// ---------------------------------------------------------------------------------------
// The input domain in the caller's frame: clearance and side of a point, independent of
// the quantisation and of Boost. Vertices are numbered globally; segment k runs from vertex
// k to vertex next_[k]; orient_[k] = +1 if the domain lies on the left of that direction.

class DomainIndex {
 public:
  struct Query {
    bool found = false;
    double distance = 0.0;
    bool inside = false;
  };

  explicit DomainIndex(const PlanarDomain& domain) {
    std::vector<std::uint32_t> loopOf;
    std::vector<std::uint32_t> loopStart;
    for (const auto& loop : domain.loops) {
      const auto start = static_cast<std::uint32_t>(points_.size());
      for (const Vec2& p : loop) {
        if (points_.size() > start && points_.back() == p) continue;  // zero-length segment
        points_.push_back(p);
      }
      while (points_.size() > start + 1 && points_.back() == points_[start]) points_.pop_back();
      const auto end = static_cast<std::uint32_t>(points_.size());
      if (end - start < 2) {  // cannot happen after the grid checks; keep the index sane
        points_.resize(start);
        continue;
      }
      loopStart.push_back(start);
      for (std::uint32_t i = start; i < end; ++i) {
        next_.push_back(i + 1 < end ? i + 1 : start);
        prev_.push_back(i > start ? i - 1 : end - 1);
        loopOf.push_back(static_cast<std::uint32_t>(loopStart.size() - 1));
      }
    }
    loopStart.push_back(static_cast<std::uint32_t>(points_.size()));
    std::vector<Vec2> a(points_.size());
    std::vector<Vec2> b(points_.size());
    for (std::size_t k = 0; k < points_.size(); ++k) {
      a[k] = points_[k];
      b[k] = points_[next_[k]];
    }
    tree_ = SegmentTree(std::move(a), std::move(b));

    // Orientation: the domain lies on the left of a loop iff (its nesting depth is even) ==
    // (it turns counter-clockwise). Depth parity = crossings of a ray from one of its
    // vertices with the other loops (which do not touch it).
    orient_.assign(points_.size(), 1);
    const std::size_t loops = loopStart.size() - 1;
    for (std::size_t l = 0; l < loops; ++l) {
      const std::uint32_t s = loopStart[l];
      const std::uint32_t e = loopStart[l + 1];
      double area2 = 0.0;
      for (std::uint32_t i = s; i < e; ++i) {
        area2 += cross(points_[i] - points_[s], points_[next_[i]] - points_[s]);
      }
      const Vec2 v = points_[s];
      int crossings = 0;
      if (loops > 1) {
        Box ray;
        ray.x0 = v.x;
        ray.x1 = std::numeric_limits<double>::infinity();
        ray.y0 = ray.y1 = v.y;
        tree_.forEachOverlapping(ray, [&](std::uint32_t k) {
          if (loopOf[k] == l) return;
          const Vec2 p = points_[k];
          const Vec2 q = points_[next_[k]];
          if ((p.y > v.y) == (q.y > v.y)) return;
          const double xCross = p.x + (v.y - p.y) * (q.x - p.x) / (q.y - p.y);
          if (xCross > v.x) ++crossings;
        });
      }
      const bool even = crossings % 2 == 0;
      const int o = (even == (area2 > 0.0)) ? 1 : -1;
      for (std::uint32_t i = s; i < e; ++i) orient_[i] = o;
    }
  }

  // Distance from p to the boundary and whether p is inside, if the boundary is within
  // maxDistance of p.
  Query query(Vec2 p, double maxDistance) const {
    const SegmentTree::Hit hit = tree_.nearest(p, sq(maxDistance));
    Query result;
    if (!hit.found) return result;
    result.found = true;
    result.distance = std::sqrt(hit.distance2);
    const std::uint32_t k = hit.segment;
    const std::uint32_t n = next_[k];
    double side = 0.0;
    if (hit.t > 0.0 && hit.t < 1.0) {
      side = cross(points_[n] - points_[k], p - points_[k]) * orient_[k];
    } else {
      const std::uint32_t v = hit.t == 0.0 ? k : n;
      Vec2 before = points_[prev_[v]];
      Vec2 after = points_[next_[v]];
      if (orient_[v] < 0) std::swap(before, after);
      side = wedgeSide(before, points_[v], after, p);
    }
    result.inside = side > 0.0;
    return result;
  }

 private:
  std::vector<Vec2> points_;
  std::vector<std::uint32_t> next_;
  std::vector<std::uint32_t> prev_;
  std::vector<int> orient_;
  SegmentTree tree_;
};

// ---------------------------------------------------------------------------------------
// Integer scaling. grid = (Rot(theta) (x - centre) - gridCentre) / step; world is the
// inverse. Both are affine, so Bezier control points map exactly (up to rounding).

struct Frame {
  Vec2 centre;      // rotation centre (caller's frame)
  Vec2 gridCentre;  // centre of the rotated bounding box
  double step = 1.0;
  double cosT = 1.0;
  double sinT = 0.0;

  Vec2 rotated(Vec2 x) const {
    const Vec2 d = x - centre;
    return {cosT * d.x - sinT * d.y, sinT * d.x + cosT * d.y};
  }
  Vec2 toGrid(Vec2 x) const {
    const Vec2 r = rotated(x) - gridCentre;
    return {r.x / step, r.y / step};
  }
  Vec2 toWorld(Vec2 g) const {
    const Vec2 r = gridCentre + g * step;
    return centre + Vec2{cosT * r.x + sinT * r.y, -sinT * r.x + cosT * r.y};
  }
};

struct GridPoint {
  std::int64_t x = 0;
  std::int64_t y = 0;
  friend bool operator==(const GridPoint&, const GridPoint&) = default;
};

std::int64_t crossI(GridPoint o, GridPoint a, GridPoint b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}
int signOf(std::int64_t v) { return (v > 0) - (v < 0); }

bool onSegmentI(GridPoint a, GridPoint b, GridPoint p) {  // p collinear with a-b
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

// Exact closed-segment intersection test (touching counts).
bool segmentsMeet(GridPoint a, GridPoint b, GridPoint c, GridPoint d) {
  const int o1 = signOf(crossI(a, b, c));
  const int o2 = signOf(crossI(a, b, d));
  const int o3 = signOf(crossI(c, d, a));
  const int o4 = signOf(crossI(c, d, b));
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && onSegmentI(a, b, c)) || (o2 == 0 && onSegmentI(a, b, d)) ||
         (o3 == 0 && onSegmentI(c, d, a)) || (o4 == 0 && onSegmentI(c, d, b));
}

// The cleaned, checked, re-oriented integer domain: vertex i, segment i = (i, next[i]) with
// the domain on its left.
struct GridDomain {
  Frame frame;
  std::vector<GridPoint> points;
  std::vector<std::uint32_t> next;
  std::vector<std::uint32_t> prev;
  std::vector<std::uint32_t> loopOf;
  std::size_t components = 0;  // loops at even nesting depth: one per domain component

  Vec2 at(std::uint32_t i) const {
    return {static_cast<double>(points[i].x), static_cast<double>(points[i].y)};
  }
  Vec2 world(std::uint32_t i) const { return frame.toWorld(at(i)); }
};

Frame makeFrame(const PlanarDomain& domain, double theta, double gridStep) {
  Frame f;
  f.cosT = std::cos(theta);
  f.sinT = std::sin(theta);
  if (gridStep > 0.0) {
    f.step = gridStep;
    return f;  // about the origin, no re-centring: integer input is replayed exactly
  }
  Box box;
  for (const auto& loop : domain.loops)
    for (const Vec2& p : loop) box.add(p);
  f.centre = {0.5 * (box.x0 + box.x1), 0.5 * (box.y0 + box.y1)};
  Box rotatedBox;
  for (const auto& loop : domain.loops)
    for (const Vec2& p : loop) rotatedBox.add(f.rotated(p));
  f.gridCentre = {0.5 * (rotatedBox.x0 + rotatedBox.x1), 0.5 * (rotatedBox.y0 + rotatedBox.y1)};
  const double half =
      0.5 * std::max(rotatedBox.x1 - rotatedBox.x0, rotatedBox.y1 - rotatedBox.y0);
  if (!(half > 0.0)) throw Error("medialAxis: all points of the domain coincide");
  f.step = half / kGridHalfRange;
  return f;
}

GridDomain quantise(const PlanarDomain& domain, const Frame& frame) {
  GridDomain g;
  g.frame = frame;
  std::vector<std::uint32_t> loopStart;
  std::vector<bool> ccw;
  for (std::size_t l = 0; l < domain.loops.size(); ++l) {
    const auto& loop = domain.loops[l];
    std::vector<GridPoint> pts;
    pts.reserve(loop.size());
    for (const Vec2& p : loop) {
      const Vec2 q = frame.toGrid(p);
      const double rx = std::nearbyint(q.x);
      const double ry = std::nearbyint(q.y);
      if (!(std::abs(rx) <= static_cast<double>(kGridLimit)) ||
          !(std::abs(ry) <= static_cast<double>(kGridLimit))) {
        throw Error(fmt::format(
            "medialAxis: point ({}, {}) of loop {} is outside the integer range |x| / gridStep "
            "<= 2^29 (gridStep {})",
            p.x, p.y, l, frame.step));
      }
      const GridPoint gp{static_cast<std::int64_t>(rx), static_cast<std::int64_t>(ry)};
      if (!pts.empty() && pts.back() == gp) continue;  // coincident on the grid
      pts.push_back(gp);
    }
    while (pts.size() > 1 && pts.back() == pts.front()) pts.pop_back();
    // Drop points continuing their neighbours' line, all at once: the direction from a kept
    // point to its new neighbour is the direction to its old one, so one pass suffices.
    const std::size_t m = pts.size();
    std::vector<GridPoint> kept;
    kept.reserve(m);
    for (std::size_t i = 0; i < m && m >= 3; ++i) {
      const GridPoint a = pts[(i + m - 1) % m];
      const GridPoint b = pts[i];
      const GridPoint c = pts[(i + 1) % m];
      const std::int64_t turn = crossI(a, b, c);
      const std::int64_t along = (b.x - a.x) * (c.x - b.x) + (b.y - a.y) * (c.y - b.y);
      if (turn == 0 && along < 0) {
        const Vec2 w = frame.toWorld({static_cast<double>(b.x), static_cast<double>(b.y)});
        throw Error(fmt::format(
            "medialAxis: loop {} folds back on itself (a zero-width spike) at ({}, {})", l, w.x,
            w.y));
      }
      if (turn == 0) continue;
      kept.push_back(b);
    }
    if (kept.size() < 3) {
      throw Error(fmt::format(
          "medialAxis: loop {} is degenerate: fewer than 3 distinct, non-collinear points on "
          "the integer grid (step {})",
          l, frame.step));
    }
    // Orientation from the lowest-leftmost vertex, which is strictly convex (exact).
    std::size_t low = 0;
    for (std::size_t i = 1; i < kept.size(); ++i) {
      if (kept[i].x < kept[low].x || (kept[i].x == kept[low].x && kept[i].y < kept[low].y)) {
        low = i;
      }
    }
    const std::size_t k = kept.size();
    ccw.push_back(crossI(kept[(low + k - 1) % k], kept[low], kept[(low + 1) % k]) > 0);
    const auto start = static_cast<std::uint32_t>(g.points.size());
    loopStart.push_back(start);
    const auto end = static_cast<std::uint32_t>(start + k);
    for (std::uint32_t i = start; i < end; ++i) {
      g.points.push_back(kept[i - start]);
      g.next.push_back(i + 1 < end ? i + 1 : start);
      g.prev.push_back(i > start ? i - 1 : end - 1);
      g.loopOf.push_back(static_cast<std::uint32_t>(l));
    }
  }
  loopStart.push_back(static_cast<std::uint32_t>(g.points.size()));

  const std::size_t n = g.points.size();
  std::vector<Vec2> a(n);
  std::vector<Vec2> b(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    a[i] = g.at(i);
    b[i] = g.at(g.next[i]);
  }
  const SegmentTree tree(std::move(a), std::move(b));

  // Boost's contract: segments meet only at shared end points. Consecutive segments share
  // one point and, without spikes, nothing else.
  for (std::uint32_t i = 0; i < n; ++i) {
    Box box;
    box.add(g.at(i));
    box.add(g.at(g.next[i]));
    tree.forEachOverlapping(box, [&](std::uint32_t j) {
      if (j <= i || j == g.next[i] || i == g.next[j]) return;
      if (segmentsMeet(g.points[i], g.points[g.next[i]], g.points[j], g.points[g.next[j]])) {
        const Vec2 p = g.world(i);
        const Vec2 q = g.world(j);
        throw Error(fmt::format(
            "medialAxis: boundary segments touch or cross (loop {} at ({}, {}) and loop {} at "
            "({}, {})); loops must be simple and disjoint, also on the integer grid (step {})",
            g.loopOf[i], p.x, p.y, g.loopOf[j], q.x, q.y, g.frame.step));
      }
    });
  }

  // Re-orient: domain on the left iff (nesting depth even) == counter-clockwise. The depth
  // parity is the parity of the crossings of a rightward ray from one vertex with the other
  // loops' segments (half-open in y; exact: the ray's origin is on no other loop).
  // All parities first: the tree indexes segment j as (j, next[j]) before any swap.
  const std::size_t loops = loopStart.size() - 1;
  std::vector<bool> reverse(loops, false);
  for (std::size_t l = 0; l < loops; ++l) {
    int crossings = 0;
    if (loops > 1) {
      const GridPoint v = g.points[loopStart[l]];
      Box ray;
      ray.x0 = static_cast<double>(v.x);
      ray.x1 = std::numeric_limits<double>::infinity();
      ray.y0 = ray.y1 = static_cast<double>(v.y);
      tree.forEachOverlapping(ray, [&](std::uint32_t j) {
        if (g.loopOf[j] == l) return;
        const GridPoint p = g.points[j];
        const GridPoint q = g.points[g.next[j]];
        if ((p.y > v.y) == (q.y > v.y)) return;
        const std::int64_t c = (q.x - p.x) * (v.y - p.y) - (v.x - p.x) * (q.y - p.y);
        if ((c > 0) == (q.y > p.y)) ++crossings;  // crossing abscissa > v.x
      });
    }
    reverse[l] = (crossings % 2 == 0) != ccw[l];
    if (crossings % 2 == 0) ++g.components;
  }
  for (std::size_t l = 0; l < loops; ++l) {
    if (!reverse[l]) continue;
    for (std::uint32_t i = loopStart[l]; i < loopStart[l + 1]; ++i) {
      std::swap(g.next[i], g.prev[i]);
    }
  }
  return g;
}

// ---------------------------------------------------------------------------------------
// Output structure for boost::polygon::voronoi_builder: one record per edge (pair of
// half-edges) with the two sites and the two end vertices, nothing else. It replaces
// voronoi_diagram, whose _build() walks rot_next cycles that loop forever on some inputs
// (boostorg/polygon#49); we need no topology beyond the end-vertex ids.

class EdgeRecorder {
 public:
  struct Site {
    std::uint32_t index = 0;  // insertion index = segment id
    boost::polygon::SourceCategory category = boost::polygon::SOURCE_CATEGORY_SINGLE_POINT;
  };
  struct Edge {
    // vertex[0]: start of the half-edge in site[0]'s cell; vertex[1]: its end (the start of
    // the twin). -1: at infinity.
    std::array<std::int32_t, 2> vertex{-1, -1};
    std::array<Site, 2> site{};
  };

  std::deque<Edge> edges;  // a deque: the builder keeps pointers into the records
  std::vector<Vec2> vertices;

  void _reserve(std::size_t sites) { vertices.reserve(2 * sites); }

  template <typename CT>
  void _process_single_site(const boost::polygon::detail::site_event<CT>&) {}

  template <typename CT>
  std::pair<void*, void*> _insert_new_edge(const boost::polygon::detail::site_event<CT>& site1,
                                           const boost::polygon::detail::site_event<CT>& site2) {
    edges.push_back(Edge{std::array<std::int32_t, 2>{-1, -1},
                         std::array<Site, 2>{site(site1), site(site2)}});
    Edge& e = edges.back();
    return {&e.vertex[0], &e.vertex[1]};
  }

  template <typename CT1, typename CT2>
  std::pair<void*, void*> _insert_new_edge(const boost::polygon::detail::site_event<CT1>& site1,
                                           const boost::polygon::detail::site_event<CT1>& site3,
                                           const boost::polygon::detail::circle_event<CT2>& circle,
                                           void* data12, void* data23) {
    // As voronoi_diagram: the two bisectors meeting at the circle event start (vertex0) at
    // the new vertex, and so does the new bisector's second half-edge.
    const auto v = static_cast<std::int32_t>(vertices.size());
    vertices.push_back({static_cast<double>(circle.x()), static_cast<double>(circle.y())});
    *static_cast<std::int32_t*>(data12) = v;
    *static_cast<std::int32_t*>(data23) = v;
    edges.push_back(Edge{std::array<std::int32_t, 2>{-1, v},
                         std::array<Site, 2>{site(site1), site(site3)}});
    Edge& e = edges.back();
    return {&e.vertex[0], &e.vertex[1]};
  }

  void _build() {}

 private:
  template <typename CT>
  static Site site(const boost::polygon::detail::site_event<CT>& s) {
    return {static_cast<std::uint32_t>(s.initial_index()), s.source_category()};
  }
};

// ---------------------------------------------------------------------------------------
// Interior edges.

struct Feature {
  bool point = true;
  std::uint32_t id = 0;  // point: vertex id; segment: segment id (its start vertex)
};

struct Build {
  MedialAxis axis;
  std::vector<std::array<std::int32_t, 2>> vertices;  // per edge: Boost's end-vertex ids
  std::size_t vertexCount = 0;
  std::string failure;  // empty: structurally sound
};

class Extractor {
 public:
  explicit Extractor(const GridDomain& g) : g_(g) {}

  Build run(const EdgeRecorder& rec) {
    Build out;
    out.axis.boundarySegments = g_.points.size();
    out.axis.quantum = g_.frame.step;
    out.axis.tolerance = g_.frame.step;
    out.vertexCount = rec.vertices.size();

    // Vertices joined by edges shorter than kShortEdge are one vertex (Boost splits
    // degenerate vertices, e.g. the centre of a square, into two joined by a null edge).
    parent_.resize(rec.vertices.size());
    std::iota(parent_.begin(), parent_.end(), std::int32_t{0});
    for (const auto& e : rec.edges) {
      if (e.vertex[0] < 0 || e.vertex[1] < 0) continue;
      if (norm(vertexAt(rec, e.vertex[1]) - vertexAt(rec, e.vertex[0])) <= kShortEdge) {
        unite(e.vertex[0], e.vertex[1]);
      }
    }
    std::vector<int> degree(rec.vertices.size(), 0);
    struct End {
      std::int32_t vertex;
      double radius;  // grid units
    };
    std::vector<End> ends;

    for (const auto& e : rec.edges) {
      const Feature fa = feature(e.site[0]);
      const Feature fb = feature(e.site[1]);
      if (!isPrimary(fa, fb)) continue;
      const bool finite0 = e.vertex[0] >= 0;
      const bool finite1 = e.vertex[1] >= 0;
      if (!finite0 || !finite1) {
        // Infinite edges lie outside a bounded domain; one starting well inside means the
        // diagram is broken (boostorg/polygon#72).
        if (finite0 != finite1 && out.failure.empty()) {
          const Vec2 x = vertexAt(rec, finite0 ? e.vertex[0] : e.vertex[1]);
          if (side(fa, x) > 1.0 && side(fb, x) > 1.0) {
            out.failure = describe("an infinite Voronoi edge starts inside the domain", x);
          }
        }
        continue;
      }
      const Vec2 p0 = vertexAt(rec, e.vertex[0]);
      const Vec2 p1 = vertexAt(rec, e.vertex[1]);
      if (norm(p1 - p0) <= kShortEdge) continue;
      // Which side of the boundary: each site decides at the chord's midpoint, which lies
      // in the edge's convex hull, inside both sites' cells (convex near each site).
      const Vec2 mid = (p0 + p1) * 0.5;
      const double sa = side(fa, mid);
      const double sb = side(fb, mid);
      if ((sa > kSideEps && sb < -kSideEps) || (sa < -kSideEps && sb > kSideEps)) {
        if (out.failure.empty()) {
          out.failure = describe("the two sites of an edge disagree on its side", mid);
        }
        continue;
      }
      if (!(sa > kSideEps && sb > kSideEps)) continue;  // outside, or null
      MedialEdge edge;
      if (!makeEdge(fa, fb, p0, p1, edge)) {
        if (out.failure.empty()) out.failure = describe("a degenerate parabolic edge", mid);
        continue;
      }
      toWorld(edge);
      ++degree[static_cast<std::size_t>(find(e.vertex[0]))];
      ++degree[static_cast<std::size_t>(find(e.vertex[1]))];
      ends.push_back({e.vertex[0], edge.radiusStart / g_.frame.step});
      ends.push_back({e.vertex[1], edge.radiusEnd / g_.frame.step});
      out.axis.edges.push_back(edge);
      out.vertices.push_back(e.vertex);
    }
    // Every vertex inside the domain meets >= 2 medial axis edges (a Voronoi vertex meets
    // 3 bisectors, at most one of them secondary); only the ends at convex vertices
    // (radius 0) are dead ends. A dead end elsewhere means missing edges (#43).
    for (const End& end : ends) {
      if (!out.failure.empty()) break;
      if (degree[static_cast<std::size_t>(find(end.vertex))] < 2 && end.radius > 1.0) {
        out.failure =
            describe("a medial axis vertex inside the domain is a dead end (missing edges)",
                     vertexAt(rec, end.vertex));
      }
    }
    if (out.failure.empty() && out.axis.edges.empty()) {
      out.failure = "the diagram has no edge inside the domain";
    }
    // The medial axis of a connected domain is connected (a deformation retract of it), and
    // the domain has one component per loop at even nesting depth: a different count of
    // connected pieces means missing edges.
    if (out.failure.empty()) {
      for (const auto& v : out.vertices) unite(v[0], v[1]);
      std::vector<std::int32_t> roots;
      roots.reserve(2 * out.vertices.size());
      for (const auto& v : out.vertices) {
        roots.push_back(find(v[0]));
        roots.push_back(find(v[1]));
      }
      std::sort(roots.begin(), roots.end());
      const auto pieces =
          static_cast<std::size_t>(std::unique(roots.begin(), roots.end()) - roots.begin());
      if (pieces != g_.components) {
        out.failure = fmt::format(
            "the medial axis has {} connected pieces but the domain {} components (missing "
            "edges)",
            pieces, g_.components);
      }
    }
    return out;
  }

 private:
  Vec2 vertexAt(const EdgeRecorder& rec, std::int32_t v) const {
    return rec.vertices[static_cast<std::size_t>(v)];
  }

  std::string describe(const char* what, Vec2 gridPoint) const {
    const Vec2 w = g_.frame.toWorld(gridPoint);
    return fmt::format("{} near ({}, {})", what, w.x, w.y);
  }

  Feature feature(const EdgeRecorder::Site& s) const {
    switch (s.category) {
      case boost::polygon::SOURCE_CATEGORY_SEGMENT_START_POINT:
        return {true, s.index};
      case boost::polygon::SOURCE_CATEGORY_SEGMENT_END_POINT:
        return {true, g_.next[s.index]};
      default:
        return {false, s.index};
    }
  }

  bool isPrimary(Feature a, Feature b) const {
    if (a.point == b.point) return true;
    const Feature p = a.point ? a : b;
    const Feature s = a.point ? b : a;
    return p.id != s.id && p.id != g_.next[s.id];
  }

  // > 0: x is on the domain side of the feature (see wedgeSide), in grid steps.
  double side(Feature f, Vec2 x) const {
    if (f.point) return wedgeSide(g_.at(g_.prev[f.id]), g_.at(f.id), g_.at(g_.next[f.id]), x);
    const Vec2 a = g_.at(f.id);
    return cross(unit(g_.at(g_.next[f.id]) - a), x - a);
  }

  // Edge geometry in grid units from Boost's end vertices p0, p1, which are projected onto
  // the exact bisector of the two sites (Boost's vertices are within 128 ulps of it).
  bool makeEdge(Feature fa, Feature fb, Vec2 p0, Vec2 p1, MedialEdge& edge) const {
    edge.siteA = site(fa);
    edge.siteB = site(fb);
    if (!fa.point && !fb.point) {
      // Line/line, eq (15). With left unit normals n1, n2 the bisector inside is
      // n1.(x - a1) = n2.(x - a2) (both distances positive): a line along n1 + n2.
      const Vec2 a1 = g_.at(fa.id);
      const Vec2 a2 = g_.at(fb.id);
      const Vec2 n1 = leftNormal(fa.id);
      const Vec2 n2 = leftNormal(fb.id);
      const Vec2 gap = n1 - n2;
      const double gap2 = dot(gap, gap);
      auto snap = [&](Vec2 x) {
        if (gap2 < 1e-24) return x;  // same-direction parallel lines: not an interior edge
        const double f = dot(n1, x - a1) - dot(n2, x - a2);
        return x - gap * (f / gap2);
      };
      const Vec2 q0 = snap(p0);
      const Vec2 q1 = snap(p1);
      const double r0 = 0.5 * (dot(n1, q0 - a1) + dot(n2, q0 - a2));
      const double r1 = 0.5 * (dot(n1, q1 - a1) + dot(n2, q1 - a2));
      // 2 psi = angle between the lines as they meet on the domain side; |n1 + n2| = 2 sin psi.
      const double sinPsi = 0.5 * norm(n1 + n2);
      edge.kind = MedialEdge::Kind::linear;
      edge.bisector = MedialEdge::Bisector::lineLine;
      edge.control = {q0, q1, q1};
      edge.radiusStart = r0;
      edge.radiusEnd = r1;
      if (sinPsi < 1e-9) {  // parallel: R constant (the paper's remark after eq (15))
        edge.d0 = r0;
        edge.d1 = r1;
        edge.sinPsi = 1.0;
      } else {  // R = d sin(psi), d the distance from the lines' intersection
        edge.d0 = r0 / sinPsi;
        edge.d1 = r1 / sinPsi;
        edge.sinPsi = sinPsi;
      }
      return true;
    }
    if (fa.point && fb.point) {
      // Point/point, eq (16): the perpendicular bisector through c = (a + b) / 2.
      const Vec2 a = g_.at(fa.id);
      const Vec2 b = g_.at(fb.id);
      const Vec2 c = (a + b) * 0.5;
      const Vec2 ab = b - a;
      const Vec2 w = unit(Vec2{-ab.y, ab.x});
      const double d0 = dot(w, p0 - c);
      const double d1 = dot(w, p1 - c);
      const double h = 0.5 * norm(ab);
      const Vec2 q0 = c + w * d0;
      const Vec2 q1 = c + w * d1;
      edge.kind = MedialEdge::Kind::linear;
      edge.bisector = MedialEdge::Bisector::pointPoint;
      edge.control = {q0, q1, q1};
      edge.radiusStart = std::hypot(d0, h);
      edge.radiusEnd = std::hypot(d1, h);
      edge.d0 = d0;
      edge.d1 = d1;
      edge.halfGap = h;
      return true;
    }
    // Point/line, eq (17): a parabola with focus f and directrix the segment's line. In the
    // segment's frame (s along it from a, h the height on the domain side) the parabola is
    // h(s) = ((s - sf)^2 + hf^2) / (2 hf); s linear in t makes it a quadratic Bezier curve,
    // whose middle control point is where the end tangents meet:
    // (s0 + s1) / 2, h(s0) + h'(s0) (s1 - s0) / 2 = ((s0 - sf)(s1 - sf) + hf^2) / (2 hf).
    const Feature fp = fa.point ? fa : fb;
    const Feature fs = fa.point ? fb : fa;
    edge.siteA = site(fp);
    edge.siteB = site(fs);
    const Vec2 a = g_.at(fs.id);
    const Vec2 u = unit(g_.at(g_.next[fs.id]) - a);
    const Vec2 n{-u.y, u.x};
    const Vec2 f = g_.at(fp.id);
    const double sf = dot(f - a, u);
    const double hf = dot(f - a, n);
    if (!(hf > 0.0)) return false;
    const double s0 = dot(p0 - a, u);
    const double s1 = dot(p1 - a, u);
    const double h0 = (sq(s0 - sf) + sq(hf)) / (2.0 * hf);
    const double h2 = (sq(s1 - sf) + sq(hf)) / (2.0 * hf);
    const double h1 = ((s0 - sf) * (s1 - sf) + sq(hf)) / (2.0 * hf);
    edge.kind = MedialEdge::Kind::parabolic;
    edge.bisector = MedialEdge::Bisector::pointLine;
    edge.control = {a + u * s0 + n * h0, a + u * (0.5 * (s0 + s1)) + n * h1, a + u * s1 + n * h2};
    edge.radiusStart = h0;
    edge.radiusEnd = h2;
    return true;
  }

  Vec2 leftNormal(std::uint32_t segment) const {
    const Vec2 u = unit(g_.at(g_.next[segment]) - g_.at(segment));
    return {-u.y, u.x};
  }

  // Sites in grid coordinates (mapped to the caller's frame by toWorld).
  MedialSite site(Feature f) const {
    MedialSite s;
    s.kind = f.point ? MedialSite::Kind::point : MedialSite::Kind::segment;
    s.a = g_.at(f.id);
    s.b = f.point ? s.a : g_.at(g_.next[f.id]);
    return s;
  }

  void toWorld(MedialEdge& e) const {
    const Frame& fr = g_.frame;
    for (Vec2& c : e.control) c = fr.toWorld(c);
    if (e.kind == MedialEdge::Kind::linear) e.control[2] = e.control[1];
    e.siteA.a = fr.toWorld(e.siteA.a);
    e.siteA.b = e.siteA.kind == MedialSite::Kind::point ? e.siteA.a : fr.toWorld(e.siteA.b);
    e.siteB.a = fr.toWorld(e.siteB.a);
    e.siteB.b = e.siteB.kind == MedialSite::Kind::point ? e.siteB.a : fr.toWorld(e.siteB.b);
    e.radiusStart *= fr.step;
    e.radiusEnd *= fr.step;
    e.d0 *= fr.step;
    e.d1 *= fr.step;
    e.halfGap *= fr.step;
  }

  std::int32_t find(std::int32_t v) {
    while (parent_[static_cast<std::size_t>(v)] != v) {
      auto& p = parent_[static_cast<std::size_t>(v)];
      p = parent_[static_cast<std::size_t>(p)];
      v = p;
    }
    return v;
  }
  void unite(std::int32_t a, std::int32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }

  const GridDomain& g_;
  std::vector<std::int32_t> parent_;
};

Build buildOnce(const GridDomain& g) {
  boost::polygon::voronoi_builder<std::int32_t> builder;
  for (std::uint32_t i = 0; i < g.points.size(); ++i) {
    const GridPoint a = g.points[i];
    const GridPoint b = g.points[g.next[i]];
    builder.insert_segment(static_cast<std::int32_t>(a.x), static_cast<std::int32_t>(a.y),
                           static_cast<std::int32_t>(b.x), static_cast<std::int32_t>(b.y));
  }
  EdgeRecorder recorder;
  builder.construct(&recorder);
  return Extractor(g).run(recorder);
}

double distanceToSite(const MedialSite& s, Vec2 p) {
  if (s.kind == MedialSite::Kind::point) return norm(p - s.a);
  return std::sqrt(distance2ToSegment(p, s.a, s.b, nullptr));
}

// The checks of checkMedialAxis. With `vertexIds` (Boost's vertex ids of each edge's ends),
// the clearance of a vertex shared by several edges is queried once.
MedialAxisCheck checkWithIndex(const DomainIndex& index, const MedialAxis& axis,
                               int samplesPerEdge,
                               std::span<const std::array<std::int32_t, 2>> vertexIds = {},
                               std::size_t vertexCount = 0) {
  MedialAxisCheck check;
  const int samples = std::max(samplesPerEdge, 2);
  const double tol = axis.tolerance;
  std::vector<DomainIndex::Query> cache(vertexIds.empty() ? 0 : vertexCount);
  std::vector<bool> cached(cache.size(), false);
  for (std::size_t i = 0; i < axis.edges.size(); ++i) {
    const MedialEdge& e = axis.edges[i];
    for (int k = 0; k < samples; ++k) {
      const double t = static_cast<double>(k) / static_cast<double>(samples - 1);
      const Vec2 x = pointAt(e, t);
      const double r = radiusAt(e, t);
      ++check.checkedPoints;
      DomainIndex::Query q;
      const bool end = k == 0 || k == samples - 1;
      if (end && !vertexIds.empty()) {
        const auto v = static_cast<std::size_t>(vertexIds[i][k == 0 ? 0 : 1]);
        if (!cached[v]) {
          cache[v] = index.query(x, r + kSearchSlack * tol);
          cached[v] = true;
        }
        q = cache[v];
      } else {
        q = index.query(x, r + kSearchSlack * tol);
      }
      double error = 0.0;
      double outside = 0.0;
      if (!std::isfinite(r) || !std::isfinite(x.x) || !std::isfinite(x.y)) {
        error = std::numeric_limits<double>::infinity();
      } else if (!q.found) {
        error = kSearchSlack * tol;  // at least: the clearance exceeds r + this
      } else {
        error = std::abs(r - q.distance);
        if (!q.inside) outside = q.distance;
      }
      error = std::max({error, std::abs(distanceToSite(e.siteA, x) - r),
                        std::abs(distanceToSite(e.siteB, x) - r)});
      check.worstRadiusError = std::max(check.worstRadiusError, error);
      check.worstOutside = std::max(check.worstOutside, outside);
      if (!(error <= tol) || outside > tol) {
        if (check.failures == 0) {
          check.firstFailure = fmt::format(
              "edge {} at t = {}: point ({}, {}), radius {}, clearance {}{} (tolerance {})", i,
              t, x.x, x.y, r, q.found ? fmt::format("{}", q.distance) : std::string("> radius"),
              outside > tol ? ", outside the domain" : "", tol);
        }
        ++check.failures;
        check.ok = false;
      }
    }
  }
  return check;
}

void checkInput(const PlanarDomain& domain, const MedialAxisOptions& options) {
  if (domain.loops.empty()) throw Error("medialAxis: the domain has no loop");
  for (std::size_t l = 0; l < domain.loops.size(); ++l) {
    const auto& loop = domain.loops[l];
    if (loop.size() < 3) {
      throw Error(fmt::format("medialAxis: loop {} has {} points; at least 3 are needed", l,
                              loop.size()));
    }
    for (std::size_t i = 0; i < loop.size(); ++i) {
      if (!std::isfinite(loop[i].x) || !std::isfinite(loop[i].y)) {
        throw Error(fmt::format("medialAxis: point {} of loop {} is not finite", i, l));
      }
    }
  }
  if (!std::isfinite(options.rotationRad)) {
    throw Error("medialAxis: options.rotationRad is not finite");
  }
  if (!(options.gridStep >= 0.0) || !std::isfinite(options.gridStep)) {
    throw Error("medialAxis: options.gridStep must be finite and >= 0");
  }
}

}  // namespace

Vec2 pointAt(const MedialEdge& edge, double t) {
  if (edge.kind == MedialEdge::Kind::linear) return lerp(edge.control[0], edge.control[1], t);
  const Vec2 a = lerp(edge.control[0], edge.control[1], t);
  const Vec2 b = lerp(edge.control[1], edge.control[2], t);
  return lerp(a, b, t);
}

double radiusAt(const MedialEdge& edge, double t) {
  switch (edge.bisector) {
    case MedialEdge::Bisector::lineLine:  // eq (15)
      return (edge.d0 * (1.0 - t) + edge.d1 * t) * edge.sinPsi;
    case MedialEdge::Bisector::pointPoint:  // eq (16)
      return std::hypot(edge.d0 * (1.0 - t) + edge.d1 * t, edge.halfGap);
    case MedialEdge::Bisector::pointLine:  // eq (17): |r(t) - f|, f the focus
      return norm(pointAt(edge, t) - edge.siteA.a);
  }
  return 0.0;
}

double clearance(const PlanarDomain& domain, Vec2 p) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& loop : domain.loops) {
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec2 a = loop[i];
      const Vec2 b = loop[i + 1 < loop.size() ? i + 1 : 0];
      best = std::min(best, distance2ToSegment(p, a, b, nullptr));
    }
  }
  return std::sqrt(best);
}

bool insideDomain(const PlanarDomain& domain, Vec2 p) {
  bool inside = false;
  for (const auto& loop : domain.loops) {
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec2 a = loop[i];
      const Vec2 b = loop[i + 1 < loop.size() ? i + 1 : 0];
      if ((a.y > p.y) == (b.y > p.y)) continue;
      const double xCross = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
      if (xCross > p.x) inside = !inside;
    }
  }
  return inside;
}

MedialAxisCheck checkMedialAxis(const PlanarDomain& domain, const MedialAxis& axis,
                                int samplesPerEdge) {
  const DomainIndex index(domain);
  return checkWithIndex(index, axis, samplesPerEdge);
}

MedialAxis medialAxis(const PlanarDomain& domain, const MedialAxisOptions& options) {
  checkInput(domain, options);
  const int attempts = 1 + std::max(options.maxRebuilds, 0);
  std::string lastFailure;
  std::vector<double> angles;
  std::optional<DomainIndex> index;  // built after the first quantisation accepted the input
  for (int attempt = 0; attempt < attempts; ++attempt) {
    const double theta = options.rotationRad + kRebuildStep * attempt;
    angles.push_back(theta);
    const GridDomain grid = quantise(domain, makeFrame(domain, theta, options.gridStep));
    if (!index) index.emplace(domain);
    Build build = buildOnce(grid);
    if (build.failure.empty()) {
      const MedialAxisCheck check =
          checkWithIndex(*index, build.axis, 3, build.vertices, build.vertexCount);
      if (check.ok) {
        build.axis.rebuilds = attempt;
        build.axis.rotationRad = theta;
        return std::move(build.axis);
      }
      build.failure = check.firstFailure;
    }
    lastFailure = build.failure;
  }
  throw Error(fmt::format(
      "medialAxis: Boost.Polygon's Voronoi diagram failed validation in all {} builds "
      "(rotations {} rad); last failure: {}",
      attempts, fmt::join(angles, ", "), lastFailure));
}

}  // namespace scallop
