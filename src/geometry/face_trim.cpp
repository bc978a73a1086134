// A trimmed face's domain in its parameter plane (see face_trim.hpp).

#include "scallop/geometry/face_trim.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <limits>
#include <utility>

#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {

namespace {

// An arc's homogeneous poles without allocation: halving runs in the hot loops of the
// distance search and the simulated cut (a thread's stack of them is reused).
struct Poles {
  std::array<std::array<double, 3>, kMaxTrimPoles> p;
  std::size_t n = 0;
  int depth = 0;
};

Poles polesOf(const TrimArc& arc) {
  if (arc.empty() || arc.size() > kMaxTrimPoles)
    throw Error(fmt::format("trimming arc: {} poles; 1 to {} are supported", arc.size(), kMaxTrimPoles));
  Poles poles;
  std::copy(arc.begin(), arc.end(), poles.p.begin());
  poles.n = arc.size();
  return poles;
}

template <class Range>
ParameterBox boxOfPoles(const Range& poles, std::size_t n) {
  ParameterBox box{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i < n; ++i) {
    const double u = poles[i][0] / poles[i][2], v = poles[i][1] / poles[i][2];
    box = {std::min(box.u0, u), std::max(box.u1, u), std::min(box.v0, v), std::max(box.v1, v)};
  }
  return box;
}

// A stack of arcs' poles for the halving loops, kept per thread (no allocation once grown);
// only each entry's first n poles are ever copied.
class PoleStack {
 public:
  void clear() { size_ = 0; }
  bool empty() const { return size_ == 0; }
  void push(const Poles& poles) { copy(poles, slot()); }
  // Pops the top into `out`.
  void pop(Poles& out) { copy(entries_[--size_], out); }
  // Pushes the piece [lo, hi] of `poles` (0 <= lo < hi <= 1), one level deeper: de Casteljau
  // at lo keeping [lo, 1], then at (hi - lo) / (1 - lo) of that keeping its start. `poles`
  // is used up.
  void pushPiece(Poles& poles, double lo, double hi) {
    const std::size_t n = poles.n;
    auto& p = poles.p;
    if (lo > 0.0) {
      // In place, level by level: after level j, p[n-1-j] is the right piece's pole n-1-j,
      // and later levels only write below it.
      for (std::size_t level = 1; level < n; ++level)
        for (std::size_t i = 0; i + level < n; ++i)
          for (std::size_t c = 0; c < 3; ++c) p[i][c] = (1.0 - lo) * p[i][c] + lo * p[i + 1][c];
    }
    if (hi < 1.0) {
      // Each level's points written from the top down, at the place of the later of the two
      // they come from: after level j, p[j] is the left piece's pole j, and later levels only
      // write above it.
      const double t = (hi - lo) / (1.0 - lo);
      for (std::size_t level = 1; level < n; ++level)
        for (std::size_t i = n - 1; i >= level; --i)
          for (std::size_t c = 0; c < 3; ++c) p[i][c] = (1.0 - t) * p[i - 1][c] + t * p[i][c];
    }
    ++poles.depth;
    push(poles);
  }
  // Pushes the two halves of `poles` at t = 1/2 (de Casteljau on the homogeneous poles): the
  // left half's poles are the first points of each level, the right half's the last
  // (reversed). `poles` is used up.
  void pushHalves(Poles& poles) {
    const std::size_t n = poles.n;
    if (size_ + 2 > entries_.size()) entries_.resize(entries_.size() + 64);  // before any reference is taken
    Poles& left = slot();
    Poles& right = slot();
    left.n = right.n = n;
    left.depth = right.depth = poles.depth + 1;
    for (std::size_t level = 0; level < n; ++level) {
      left.p[level] = poles.p[0];
      right.p[n - 1 - level] = poles.p[n - 1 - level];
      for (std::size_t i = 0; i + 1 < n - level; ++i)
        for (std::size_t c = 0; c < 3; ++c) poles.p[i][c] = 0.5 * (poles.p[i][c] + poles.p[i + 1][c]);
    }
  }

 private:
  static void copy(const Poles& from, Poles& to) {
    std::copy_n(from.p.begin(), from.n, to.p.begin());
    to.n = from.n;
    to.depth = from.depth;
  }
  Poles& slot() {
    if (size_ == entries_.size()) entries_.resize(entries_.size() + 64);
    return entries_[size_++];
  }
  std::vector<Poles> entries_;
  std::size_t size_ = 0;
};

// The angle from a to b (vectors from p), in (-pi, pi].
double angleBetween(double ax, double ay, double bx, double by) {
  return std::atan2(ax * by - ay * bx, ax * bx + ay * by);
}

// The arc's angle about p when p lies outside its poles' box: the box, and so the arc, then
// lies in an open half-plane through p, where the angle is its ends' (no wrapping); NaN when
// p lies in the box.
template <class Range>
double angleOutsideBox(const Range& poles, std::size_t n, double u, double v) {
  const ParameterBox box = boxOfPoles(poles, n);
  if (u >= box.u0 && u <= box.u1 && v >= box.v0 && v <= box.v1) return std::numeric_limits<double>::quiet_NaN();
  const auto& a = poles[0];
  const auto& b = poles[n - 1];
  return angleBetween(a[0] / a[2] - u, a[1] / a[2] - v, b[0] / b[2] - u, b[1] / b[2] - v);
}

// Whether some arc of the trim may meet the box (mayMeet's: false is proven).
bool anyArcMayMeet(const FaceTrim& trim, const ParameterBox& box);

}  // namespace

ParameterBox poleBox(const TrimArc& arc) { return boxOfPoles(arc, arc.size()); }

double sweptAngle(const TrimArc& arc, double u, double v) {
  // Most arcs lie away from p: one box test and one angle, without halving.
  if (const double angle = angleOutsideBox(arc, arc.size(), u, v); !std::isnan(angle)) return angle;
  thread_local PoleStack stack;
  stack.clear();
  stack.push(polesOf(arc));
  double total = 0.0;
  Poles poles;
  while (!stack.empty()) {
    stack.pop(poles);
    const std::size_t n = poles.n;
    if (const double angle = angleOutsideBox(poles.p, n, u, v); !std::isnan(angle)) {
      total += angle;
      continue;
    }
    // The poles as vectors from p, their angles measured from the first.
    const double ax = poles.p[0][0] / poles.p[0][2] - u, ay = poles.p[0][1] / poles.p[0][2] - v;
    bool wedge = ax != 0.0 || ay != 0.0;
    double least = 0.0, largest = 0.0, last = 0.0;
    for (std::size_t i = 1; wedge && i < n; ++i) {
      const double bx = poles.p[i][0] / poles.p[i][2] - u, by = poles.p[i][1] / poles.p[i][2] - v;
      if (bx == 0.0 && by == 0.0) {
        wedge = false;
        break;
      }
      last = angleBetween(ax, ay, bx, by);
      least = std::min(least, last);
      largest = std::max(largest, last);
    }
    // A margin of 1e-9 rad keeps the rounding of the angles themselves out of the test.
    constexpr double kMargin = 1e-9;
    if (wedge && largest - least < std::numbers::pi - kMargin && least > -std::numbers::pi + kMargin &&
        largest < std::numbers::pi - kMargin) {
      total += last;
      continue;
    }
    if (poles.depth >= kWindingDepth) return std::numeric_limits<double>::quiet_NaN();
    stack.pushHalves(poles);
  }
  return total;
}

CellPlace classifyPoint(const FaceTrim& trim, double u, double v) {
  double total = 0.0;
  for (const TrimArc& arc : trim.arcs) {
    const double angle = sweptAngle(arc, u, v);
    if (std::isnan(angle)) return CellPlace::boundary;
    total += angle;
  }
  const double turns = std::round(total / (2.0 * std::numbers::pi));
  if (!(std::abs(total - 2.0 * std::numbers::pi * turns) <= kWindingSlackRad)) return CellPlace::boundary;
  return std::fmod(std::abs(turns), 2.0) == 1.0 ? CellPlace::inside : CellPlace::outside;
}

CellPlace classifyBox(const FaceTrim& trim, const ParameterBox& box) {
  if (anyArcMayMeet(trim, box)) return CellPlace::boundary;
  return classifyPoint(trim, 0.5 * (box.u0 + box.u1), 0.5 * (box.v0 + box.v1));
}

namespace {

// Where on [0, 1] the function sum_i B_i(t) f_i (Bernstein polynomials of degree n - 1) may
// be >= 0: the graph (t, f(t)) lies in the convex hull of the points (i / (n - 1), f_i), so
// f(t) >= 0 only for t between the least and the largest t of that hull's part where f >= 0,
// whose extremes are points with f_i >= 0 or crossings of f = 0 by the segment of two points
// of opposite signs (every pair is tried: n <= kMaxTrimPoles). Narrows [lo, hi] to it;
// false when it is empty.
bool clipToNonNegative(const std::array<double, kMaxTrimPoles>& f, std::size_t n, double& lo, double& hi) {
  // Most sides lie wholly to one side of the piece's poles: nothing to narrow, or nothing left.
  std::size_t nonNegative = 0;
  for (std::size_t i = 0; i < n; ++i) nonNegative += f[i] >= 0.0 ? 1 : 0;
  if (nonNegative == n) return true;
  if (nonNegative == 0) return false;
  double least = std::numeric_limits<double>::infinity(), largest = -least;
  const double step = 1.0 / static_cast<double>(n - 1);  // n >= 2: the signs differ
  for (std::size_t i = 0; i < n; ++i) {
    if (!(f[i] >= 0.0)) continue;
    const double ti = static_cast<double>(i) * step;
    least = std::min(least, ti);
    largest = std::max(largest, ti);
    for (std::size_t j = 0; j < n; ++j) {
      if (f[j] >= 0.0) continue;
      const double tj = static_cast<double>(j) * step;
      const double t = ti + (tj - ti) * (f[i] / (f[i] - f[j]));
      least = std::min(least, t);
      largest = std::max(largest, t);
    }
  }
  lo = std::max(lo, least);
  hi = std::min(hi, largest);
  return lo <= hi;
}

// The part of the arc's parameter interval where it may lie in the box (Bezier clipping,
// Sederberg and Nishita 1990): u >= u0 is w u - u0 w >= 0 (w > 0), a Bernstein polynomial in
// t whose coefficients are the poles' w u - u0 w; so for the box's four sides. Widened by
// kClipSlack (the rounding of the crossings and of the piece's parameters); false when the
// arc provably misses the box. `own` is the poles' box (the caller's): a side it lies wholly
// within narrows nothing and is skipped.
bool clipToBox(const Poles& poles, const ParameterBox& own, const ParameterBox& box, double& lo, double& hi) {
  constexpr double kClipSlack = 1e-9;
  const std::size_t n = poles.n;
  lo = 0.0, hi = 1.0;
  std::array<double, kMaxTrimPoles> f;  // the first n written before they are read
  const auto side = [&](bool within, std::size_t coordinate, double bound, double sign) {
    if (within) return true;
    for (std::size_t i = 0; i < n; ++i)
      f[i] = sign * (poles.p[i][coordinate] - bound * poles.p[i][2]);
    return clipToNonNegative(f, n, lo, hi);
  };
  if (!side(own.u0 >= box.u0, 0, box.u0, 1.0) || !side(own.u1 <= box.u1, 0, box.u1, -1.0) ||
      !side(own.v0 >= box.v0, 1, box.v0, 1.0) || !side(own.v1 <= box.v1, 1, box.v1, -1.0))
    return false;
  lo = std::max(0.0, lo - kClipSlack);
  hi = std::min(1.0, hi + kClipSlack);
  return true;
}

// mayMeet's loop; `clip` false: halving alone (detail::mayMeetByHalving).
bool mayMeetImpl(const TrimArc& arc, const ParameterBox& box, bool clip) {
  if (!poleBox(arc).meets(box)) return false;  // most arcs: no halving
  const double smallU = (box.u1 - box.u0) / 8.0, smallV = (box.v1 - box.v0) / 8.0;
  thread_local PoleStack stack;
  stack.clear();
  stack.push(polesOf(arc));
  Poles poles;
  while (!stack.empty()) {
    stack.pop(poles);
    const ParameterBox own = boxOfPoles(poles.p, poles.n);
    if (!own.meets(box)) continue;
    if ((own.u1 - own.u0 <= smallU && own.v1 - own.v0 <= smallV) || poles.depth >= 40) return true;
    // The piece that may lie in the box, when that is at most half the arc (each step at
    // least halves the parameter interval, so the depth still bounds it); else the halves.
    double lo = 0.0, hi = 1.0;
    if (clip && !clipToBox(poles, own, box, lo, hi)) continue;
    if (hi - lo <= 0.5) {
      stack.pushPiece(poles, lo, hi);
    } else {
      stack.pushHalves(poles);
    }
  }
  return false;
}

bool anyArcMayMeet(const FaceTrim& trim, const ParameterBox& box) {
  for (const TrimArc& arc : trim.arcs)
    if (mayMeetImpl(arc, box, true)) return true;
  return false;
}

// The image of the cell in the face's parameters, widened by the trim's margin.
ParameterBox widenedImage(const PatchTrim& trim, const ParameterCell& cell) {
  const double ua = trim.u.at(cell.u0), ub = trim.u.at(cell.u1);
  const double va = trim.v.at(cell.v0), vb = trim.v.at(cell.v1);
  return {std::min(ua, ub) - trim.margin, std::max(ua, ub) + trim.margin, std::min(va, vb) - trim.margin,
          std::max(va, vb) + trim.margin};
}

}  // namespace

bool mayMeet(const TrimArc& arc, const ParameterBox& box) { return mayMeetImpl(arc, box, true); }

namespace detail {
bool mayMeetByHalving(const TrimArc& arc, const ParameterBox& box) { return mayMeetImpl(arc, box, false); }
}  // namespace detail

AxisMap AxisMap::affine(double from, double to) {
  AxisMap map;
  map.from = from, map.to = to;
  return map;
}

AxisMap AxisMap::halfAngle(double from, double middle, double to) {
  // tan((angle - middle) / 2) at the ends: -1/2 / offset at 0, 1/2 / (slope + offset) at 1.
  const double atStart = std::tan(0.5 * (from - middle)), atEnd = std::tan(0.5 * (to - middle));
  if (!(std::abs(from - middle) < std::numbers::pi) || !(std::abs(to - middle) < std::numbers::pi) ||
      !(atStart * atEnd < 0.0))
    throw Error(fmt::format("the angles {}, {}, {} (radians) at the start, middle and end of a patch are not a "
                            "monotone arc of less than a turn",
                            from, middle, to));
  AxisMap map;
  map.kind = Kind::halfAngle;
  map.from = from, map.to = to, map.middle = middle;
  map.offset = -0.5 / atStart;
  map.slope = 0.5 / atEnd - map.offset;
  return map;
}

double AxisMap::at(double x) const {
  if (kind == Kind::affine) return from + x * (to - from);
  return middle + 2.0 * std::atan((x - 0.5) / (slope * x + offset));
}

void validateAxisMap(const AxisMap& map, const char* what) {
  bool valid = std::isfinite(map.from) && std::isfinite(map.to) && map.from != map.to;
  if (valid && map.kind == AxisMap::Kind::halfAngle) {
    // The denominator slope x + offset keeps its sign on [0, 1] (it is linear): then the map
    // is continuous and its derivative, (offset + slope / 2) / denominator^2, keeps one sign.
    valid = std::isfinite(map.middle) && std::isfinite(map.slope) && std::isfinite(map.offset) &&
            map.offset * (map.slope + map.offset) > 0.0 && map.offset + 0.5 * map.slope != 0.0;
  }
  if (!valid)
    throw Error(fmt::format("{}: maps [0, 1] onto [{}, {}]{}: not a monotone map onto an interval", what, map.from,
                            map.to,
                            map.kind == AxisMap::Kind::halfAngle
                                ? fmt::format(" by half-angles (middle {}, slope {}, offset {})", map.middle,
                                              map.slope, map.offset)
                                : std::string()));
}

CellPlace classifyCell(const PatchTrim& trim, const ParameterCell& cell) {
  if (!trim.trimmed()) return CellPlace::inside;
  return classifyBox(*trim.face, widenedImage(trim, cell));
}

bool cellMayMeetTrim(const PatchTrim& trim, const ParameterCell& cell) {
  if (!trim.trimmed()) return false;
  return anyArcMayMeet(*trim.face, widenedImage(trim, cell));
}

CellPlace placeOfPoint(const PatchTrim& trim, double s, double t) {
  if (!trim.trimmed()) return CellPlace::inside;
  return classifyPoint(*trim.face, trim.u.at(s), trim.v.at(t));
}

bool keepsPoint(const PatchTrim& trim, double s, double t) {
  if (!trim.trimmed()) return true;
  return classifyPoint(*trim.face, trim.u.at(s), trim.v.at(t)) != CellPlace::outside;
}

}  // namespace scallop
