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
  for (const TrimArc& arc : trim.arcs)
    if (mayMeet(arc, box)) return CellPlace::boundary;
  return classifyPoint(trim, 0.5 * (box.u0 + box.u1), 0.5 * (box.v0 + box.v1));
}

bool mayMeet(const TrimArc& arc, const ParameterBox& box) {
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
    stack.pushHalves(poles);
  }
  return false;
}

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
  const double ua = trim.u.at(cell.u0), ub = trim.u.at(cell.u1);
  const double va = trim.v.at(cell.v0), vb = trim.v.at(cell.v1);
  const ParameterBox box{std::min(ua, ub) - trim.margin, std::max(ua, ub) + trim.margin,
                         std::min(va, vb) - trim.margin, std::max(va, vb) + trim.margin};
  return classifyBox(*trim.face, box);
}

bool keepsPoint(const PatchTrim& trim, double s, double t) {
  if (!trim.trimmed()) return true;
  return classifyPoint(*trim.face, trim.u.at(s), trim.v.at(t)) != CellPlace::outside;
}

}  // namespace scallop
