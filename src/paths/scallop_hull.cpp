// The scallop hull and its offset in one left-to-right pass with a stack.
// See include/scallop/scallop_hull.hpp for the contract and the outline of the method.

#include "scallop/paths/scallop_hull.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <fmt/format.h>

#include "scallop/error.hpp"

namespace scallop {
namespace {

constexpr double kRelativeTolerance = 1e-12;  // tau = kRelativeTolerance * scale (header)
constexpr double kMaxToleranceOfRadius = 1e-3;  // tau / r above this is refused (header)

double arcTop(const Point2& centre, double r, double x) {
  // Upper semicircle z = c_z + sqrt(r^2 - d^2), written as (r - |d|)(r + |d|) so the value
  // stays accurate near the vertical tangents |d| = r.
  const double d = std::abs(x - centre.x);
  const double h = (r - d) * (r + d);
  return centre.z + (h > 0.0 ? std::sqrt(h) : 0.0);
}

// The top of the capsule of edge e_i = (a, b) (all centres within r of the edge) as a
// function of x over [a.x - r, b.x + r]: arc around a on [left, s0], the edge's offset line
// a + r n .. b + r n on [s0, s1], arc around b on [s1, right] (the paper's Figure 3). A
// vertical or zero-length edge is one arc around its upper end point.
struct Capsule {
  Point2 a;
  Point2 b;
  double r = 0.0;
  double nx = 0.0;  // upward unit normal of a -> b (nz > 0); unused when vertical
  double nz = 1.0;
  double s0 = 0.0;  // x range of the offset line
  double s1 = 0.0;
  bool vertical = false;

  [[nodiscard]] double left() const { return a.x - r; }
  [[nodiscard]] double right() const { return b.x + r; }
  [[nodiscard]] const Point2& upperEnd() const { return a.z >= b.z ? a : b; }
  // The point where the capsule's top ends on the right, at x = right(): level with b, or
  // with the upper end of a vertical edge.
  [[nodiscard]] const Point2& upperEndAtRight() const { return vertical ? upperEnd() : b; }

  // Point of the offset line at parameter t in [0, 1] (t = 0 above a, t = 1 above b).
  [[nodiscard]] Point2 linePoint(double t) const {
    if (t <= 0.0) return {a.x + r * nx, a.z + r * nz};
    if (t >= 1.0) return {b.x + r * nx, b.z + r * nz};
    return {a.x + r * nx + t * (b.x - a.x), a.z + r * nz + t * (b.z - a.z)};
  }
  // Line parameter of abscissa x, clamped to [0, 1]; exact 0 and 1 at the ends, so the
  // end points of a nearly vertical offset line never depend on a division by its width.
  [[nodiscard]] double lineParameter(double x) const {
    if (x <= s0) return 0.0;
    if (x >= s1) return 1.0;
    return std::clamp((x - s0) / (b.x - a.x), 0.0, 1.0);
  }

  [[nodiscard]] double top(double x) const {
    // At its two ends the top is level with a (or the upper end of a vertical edge) and
    // with b, exactly: evaluating the circle there would amplify the rounding of x - c.x
    // into an error of sqrt(2 r ulp) in z.
    if (x <= left()) return vertical ? upperEnd().z : a.z;
    if (x >= right()) return upperEndAtRight().z;
    if (vertical) return arcTop(upperEnd(), r, x);
    if (x <= s0) return arcTop(a, r, x);
    if (x >= s1) return arcTop(b, r, x);
    return linePoint(lineParameter(x)).z;
  }
};

// The capsule of a -> b with a known upward unit normal (nx, nz) (ignored if vertical).
// (A vertical capsule is stored with the normal (0, 0).)
Capsule capsuleWithNormal(const Point2& a, const Point2& b, double r, double nx, double nz) {
  Capsule c;
  c.a = a;
  c.b = b;
  c.r = r;
  if (nz == 0.0) {
    c.vertical = true;
    c.nx = 0.0;
    c.nz = 0.0;
    return c;
  }
  c.nx = nx;
  c.nz = nz;
  c.s0 = a.x + r * nx;
  c.s1 = b.x + r * nx;
  return c;
}

// An edge whose run dx is at most `verticalRun` is taken as vertical: moving its end by dx
// moves the envelope by at most dx, well inside the tolerance, while on a line a few ulps
// wide x no longer tells where along it a point is (see Stretch).
struct UnitNormal {
  double nx, nz;
};

// The upward unit normal of the (not vertical) edge a -> b: the one formula both passes use,
// so that their capsules agree bit for bit.
UnitNormal upwardNormal(const Point2& a, const Point2& b) {
  const double dx = b.x - a.x;
  const double dz = b.z - a.z;
  double length = std::sqrt(dx * dx + dz * dz);
  if (!(length > 0.0) || !std::isfinite(length)) length = std::hypot(dx, dz);
  return {-dz / length, dx / length};
}

Capsule makeCapsule(const Point2& a, const Point2& b, double r, double verticalRun) {
  if (!(b.x - a.x > verticalRun)) return capsuleWithNormal(a, b, r, 0.0, 0.0);
  const UnitNormal n = upwardNormal(a, b);
  return capsuleWithNormal(a, b, r, n.nx, n.nz);
}

// |(u, w)|^2 - r^2, written as (|u| - r)(|u| + r) + w^2 with |u| the larger component: no
// cancellation when a point lies near the extreme of a circle (one component ~ r), where
// the plain difference of squares loses all precision once r is large.
double circleExcess(double u, double w, double r) {
  u = std::abs(u);
  w = std::abs(w);
  if (u < w) std::swap(u, w);
  return (u - r) * (u + r) + w * w;
}


// Which side of the boundary of capsule a-b (radius r) point p is on, with an undecided
// band of half-width `band` around it: -1 inside (distance <= r - band), +1 outside
// (distance >= r + band), 0 too close to tell. One evaluation, no square root. For a point
// on the current envelope (the start of a stacked piece) "inside" is the same as "the
// capsule's top is on or above p": the envelope lies above the arc around a = v_k, and so
// above the capsule's lower boundary. (Points of a stacked capsule beyond its piece are
// not on the envelope: for those use isBelowTop.)
int sideOfCapsule(const Point2& p, const Point2& a, const Point2& b, double r, double band) {
  const double dx = b.x - a.x;
  const double dz = b.z - a.z;
  const double px = p.x - a.x;
  const double pz = p.z - a.z;
  const double dot = px * dx + pz * dz;
  const double length2 = dx * dx + dz * dz;
  double excess;  // distance^2 - r^2, times length2 for the line case
  double scale = 1.0;
  if (dot <= 0.0 || length2 == 0.0) {
    excess = circleExcess(px, pz, r);
  } else if (dot >= length2) {
    excess = circleExcess(p.x - b.x, p.z - b.z, r);
  } else {
    const double cross = px * dz - pz * dx;
    excess = cross * cross - (r * r) * length2;
    scale = length2;
  }
  // distance - r ~ (distance^2 - r^2) / 2r.
  const double threshold = 2.0 * r * band * scale;
  if (excess <= -threshold) return -1;
  if (excess >= threshold) return 1;
  return 0;
}


// Parameter of the foot of p on the offset line of c (0 above a, 1 above b), not clamped:
// points of the arc around a project below 0 and those of the arc around b above 1. Well
// conditioned for a line of any slope, where reading it off x is not (near-vertical).
double projectOnLine(const Capsule& c, const Point2& p) {
  const Point2 origin = c.linePoint(0.0);
  const double dx = c.b.x - c.a.x;
  const double dz = c.b.z - c.a.z;
  return ((p.x - origin.x) * dx + (p.z - origin.z) * dz) / (dx * dx + dz * dz);
}

// True when (x, z) is on or below the top of capsule c (and x within its reach).
bool isBelowTop(const Capsule& c, double x, double z) {
  return x >= c.left() && x <= c.right() && c.top(x) >= z;
}

// One analytic piece of a capsule top: an upper arc of radius r, or a straight line.
struct Feature {
  bool isArc = true;
  Point2 point;            // arc: centre; line: a point on the line
  double dx = 0.0;         // line: direction (dx > 0)
  double dz = 0.0;
};


// Points where two features meet: at most two, ordered by x. Everything is computed
// relative to `origin` so that coordinates far from zero (1e6) do not cost precision, and
// each point comes from the parametric solution, so that it is accurate even on a
// near-vertical line (where x alone would not fix z). The three cases are the paper's
// support pairs (Figure 6):
//   line-line (slope-slope): the offset lines meet where cross(p2 - p1, d2) = t cross(d1, d2);
//   arc-arc (peak-peak): equal circles meet on the perpendicular bisector of their centres,
//     at height sqrt(r^2 - d^2/4) above the midpoint; the upper point is the one reached by
//     turning c2 - c1 counter-clockwise (centres are x-ordered);
//   line-arc (peak-slope): |p + t u - c|^2 = r^2 with u the unit direction, a quadratic in t,
//     kept only where the point is on the upper half of the circle.
int featureRoots(const Feature& f, const Feature& g, double r, std::array<Point2, 2>& roots) {
  const Point2 origin = f.point;
  auto local = [&](const Point2& p) { return Point2{p.x - origin.x, p.z - origin.z}; };
  auto global = [&](double x, double z) { return Point2{origin.x + x, origin.z + z}; };
  int count = 0;
  if (!f.isArc && !g.isArc) {
    const Point2 p2 = local(g.point);
    const double denom = f.dx * g.dz - f.dz * g.dx;
    if (denom == 0.0) return 0;
    const double t = (p2.x * g.dz - p2.z * g.dx) / denom;
    roots[count++] = global(t * f.dx, t * f.dz);
    return count;
  }
  if (f.isArc && g.isArc) {
    Point2 c1{0.0, 0.0};
    Point2 c2 = local(g.point);
    if (c2.x < c1.x) std::swap(c1, c2);
    const double wx = c2.x - c1.x;
    const double wz = c2.z - c1.z;
    const double d2 = wx * wx + wz * wz;
    if (d2 == 0.0 || d2 > 4.0 * r * r) return 0;
    const double d = std::sqrt(d2);
    const double h = std::sqrt(std::max(0.0, r * r - 0.25 * d2));
    // Both arcs are upper halves: the meeting point must not lie below either centre
    // (centres one above the other meet only below the upper one).
    const double z = 0.5 * (c1.z + c2.z) + h * wx / d;
    if (z < std::max(c1.z, c2.z) - 1e-9 * r) return 0;
    roots[count++] = global(0.5 * (c1.x + c2.x) - h * wz / d, z);
    return count;
  }
  const Feature& line = f.isArc ? g : f;
  const Feature& arc = f.isArc ? f : g;
  const Point2 p = local(line.point);
  const Point2 c = local(arc.point);
  const double len = std::sqrt(line.dx * line.dx + line.dz * line.dz);  // dx > 0: no 0/0
  const double ux = line.dx / len;
  const double uz = line.dz / len;
  const double wx = p.x - c.x;
  const double wz = p.z - c.z;
  const double b = wx * ux + wz * uz;
  const double cc = (wx * wx + wz * wz) - r * r;
  const double disc = b * b - cc;
  // Within its rounding error the discriminant says "tangent": take the double root t = -b,
  // the foot of the perpendicular from the centre, which is well conditioned, where
  // sqrt(disc) would scatter the root by the square root of that error. The error: the
  // products (about epsilon r^2) and the local coordinates themselves, each off by up to
  // delta = a few ulps of the global coordinates, which moves |w|^2 by 2 |w| delta.
  constexpr double eps = std::numeric_limits<double>::epsilon();
  const double delta = 4.0 * eps * std::max({std::abs(origin.x), std::abs(origin.z),
                                             std::abs(line.point.x), std::abs(line.point.z),
                                             std::abs(arc.point.x), std::abs(arc.point.z)});
  const double discNoise = 8.0 * eps * std::max({b * b, std::abs(cc), r * r}) +
                           4.0 * (std::abs(wx) + std::abs(wz) + r) * delta;
  if (disc < -discNoise) return 0;
  std::array<double, 2> ts{-b, -b};
  int distinct = 1;
  if (disc > discNoise) {
    // Stable quadratic roots of t^2 + 2 b t + cc = 0.
    const double q = -(b + std::copysign(std::sqrt(disc), b));
    ts = {q, q != 0.0 ? cc / q : 0.0};
    distinct = 2;
  }
  for (int i = 0; i < distinct; ++i) {
    const double zOnLine = p.z + ts[i] * uz;
    if (zOnLine < c.z - 1e-9 * r) continue;  // lower half of the circle: not on the arc
    roots[count++] = global(p.x + ts[i] * ux, zOnLine);
  }
  if (count == 2 && roots[0].x > roots[1].x) std::swap(roots[0], roots[1]);
  return count;
}

// Where a point lies along capsule c's top, by its projection on the offset line (see
// projectOnLine): below 0 on the arc around a, in [0, 1] on the line, above 1 on the arc
// around b. Told by projection, not by x, so that a near-vertical line (whose x range is a
// few ulps wide) still has its own stretch.
enum class Stretch { arcA, line, arcB };

// The stretch of c's top that point p (on or near it) lies on. Where x is decisive (more
// than a rounding error from the offset line's x range) x tells; otherwise the projection
// does. Neither alone will do: x cannot tell along a near-vertical line, and the projection
// cannot tell near the arc's end point level with a vertical edge direction.
double xMargin(const Capsule& c, const Point2& p) {
  return 8.0 * std::numeric_limits<double>::epsilon() * (std::abs(p.x) + c.r);
}

Stretch stretchOf(const Capsule& c, const Point2& p) {
  if (c.vertical) return Stretch::arcA;
  const double eta = xMargin(c, p);
  if (p.x < c.s0 - eta) return Stretch::arcA;
  if (p.x > c.s1 + eta) return Stretch::arcB;
  const double t = projectOnLine(c, p);
  return t <= 0.0 ? Stretch::arcA : (t < 1.0 ? Stretch::line : Stretch::arcB);
}

// Whether p may lie on the given stretch, allowing rounding-level overshoot at its ends.
bool onStretch(const Capsule& c, Stretch stretch, const Point2& p) {
  if (c.vertical) return true;
  const double eta = 1e-9 * (c.s1 - c.s0) + xMargin(c, p);
  if (p.x < c.s0 - eta) return stretch == Stretch::arcA;
  if (p.x > c.s1 + eta) return stretch == Stretch::arcB;
  constexpr double slack = 1e-9;
  const double t = projectOnLine(c, p);
  switch (stretch) {
    case Stretch::arcA: return t <= slack;
    case Stretch::line: return t >= -slack && t <= 1.0 + slack;
    case Stretch::arcB: return t >= 1.0 - slack;
  }
  return false;
}

Feature featureOf(const Capsule& c, Stretch stretch) {
  if (c.vertical) return {true, c.upperEnd(), 0.0, 0.0};
  switch (stretch) {
    case Stretch::arcA: return {true, c.a, 0.0, 0.0};
    case Stretch::line: return {false, c.linePoint(0.0), c.b.x - c.a.x, c.b.z - c.a.z};
    case Stretch::arcB: return {true, c.b, 0.0, 0.0};
  }
  return {};
}

// The point where T's curve enters capsule K for good, on the stretch of T from `outside`
// (a point of T outside K) to `inside` (a point of T inside K, further right): the last
// meeting point of that stretch with K's top whose continuation towards `inside` is
// inside K.
Point2 crossingOnStretch(const Capsule& t, Stretch stretch, const Capsule& k, Point2 outside,
                         Point2 inside) {
  const Feature f = featureOf(t, stretch);
  // A point of the stretch between two of its points: on a line their midpoint (which stays
  // on the line however steep it is), on an arc the point above the middle abscissa.
  auto between = [&](const Point2& p, const Point2& q) {
    if (!f.isArc) return Point2{0.5 * (p.x + q.x), 0.5 * (p.z + q.z)};
    const double x = 0.5 * (p.x + q.x);
    return Point2{x, arcTop(f.point, t.r, x)};
  };
  // Position along the stretch, increasing towards `inside`.
  auto along = [&](const Point2& p) { return f.isArc ? p.x : projectOnLine(t, p); };
  const double from = along(outside);
  const double to = along(inside);
  const double slack = 1e-9 * std::abs(to - from) + 4.0 * std::numeric_limits<double>::epsilon() *
                                                      (std::abs(from) + std::abs(to) + 1.0);
  std::array<Point2, 6> roots{};
  int count = 0;
  auto collect = [&](Stretch other) {
    const Feature g = featureOf(k, other);
    if (f.isArc && g.isArc && f.point == g.point) {
      // The same arc (a vertex shared by both edges, or a repeated point): K equals T along
      // it, so it may take over where that arc begins on this stretch.
      Point2 start = outside;
      if (!k.vertical && !onStretch(k, other, start)) return;
      roots[count++] = start;
      return;
    }
    std::array<Point2, 2> found{};
    const int n = featureRoots(f, g, t.r, found);
    for (int i = 0; i < n; ++i) {
      const double position = along(found[i]);
      if (position < from - slack || position > to + slack) continue;
      if (!onStretch(k, other, found[i])) continue;
      roots[count++] = found[i];
    }
  };
  if (k.vertical) {
    collect(Stretch::arcA);
  } else {
    collect(Stretch::arcA);
    collect(Stretch::line);
    collect(Stretch::arcB);
  }
  for (int i = 1; i < count; ++i) {  // insertion sort, the furthest along first
    for (int j = i; j > 0 && along(roots[j - 1]) < along(roots[j]); --j) {
      std::swap(roots[j - 1], roots[j]);
    }
  }
  Point2 best = inside;
  for (int i = 0; i < count; ++i) {
    const Point2 root = roots[i];
    if (along(root) > along(best) || root == best) continue;
    const Point2 mid = between(root, best);
    if (!isBelowTop(k, mid.x, mid.z)) break;
    best = root;
  }
  if (!(best == inside)) return best;
  // No usable root: the curves are tangent or nearly coincide. If they touch at `inside`
  // (T's offset line running into the arc around its end point, which K shares), that is
  // the crossing: a tangent root is only known to sqrt(epsilon), the junction exactly.
  const double touch = 1e-12 * std::max({t.r, std::abs(inside.x), std::abs(inside.z)});
  if (std::abs(k.top(inside.x) - inside.z) <= touch) return inside;
  // Otherwise a double root was lost to rounding (circles around nearly equal centres):
  // bisect on the inside test.
  for (int i = 0; i < 200; ++i) {
    const Point2 mid = between(outside, inside);
    if (mid == outside || mid == inside) break;
    (isBelowTop(k, mid.x, mid.z) ? inside : outside) = mid;
  }
  return inside;
}

// The point from which capsule K is on or above capsule T, between T's points (lo, zLo) and
// (hi, zHi), given K >= T at hi. By the ordering of contacts, T's curve enters K once and
// stays inside: walk T's stretches from the right (their end points are exact: the ends of
// the offset line) with isBelowTop, then solve on the one stretch where it enters.
Point2 crossing(const Capsule& t, const Capsule& k, double lo, double hi, double zLo,
                double zHi) {
  const Point2 start{lo, zLo};
  Point2 inside{hi, zHi};
  Stretch stretch = Stretch::arcA;  // the stretch of T that ends at `inside`
  if (!t.vertical) {
    const Stretch startStretch = stretchOf(t, start);
    stretch = Stretch::arcB;
    if (startStretch != Stretch::arcB) {
      const Point2 lineEnd = t.linePoint(1.0);
      if (!(lineEnd == inside)) {
        if (!isBelowTop(k, lineEnd.x, lineEnd.z)) {
          return crossingOnStretch(t, Stretch::arcB, k, lineEnd, inside);
        }
        inside = lineEnd;
      }
      stretch = Stretch::line;
      if (startStretch == Stretch::arcA) {
        const Point2 lineStart = t.linePoint(0.0);
        if (!(lineStart == inside)) {
          if (!isBelowTop(k, lineStart.x, lineStart.z)) {
            return crossingOnStretch(t, Stretch::line, k, lineStart, inside);
          }
          inside = lineStart;
        }
        stretch = Stretch::arcA;
      }
    }
  }
  if (isBelowTop(k, start.x, start.z)) return start;
  return crossingOnStretch(t, stretch, k, start, inside);
}

// The usual hand-overs in closed form: the meeting point of one stretch of T with one of K
// (peak-peak, peak-slope, slope-peak, slope-slope). A meeting point is accepted only if it lies on both stretches,
// strictly inside T's piece (lo, hi), away from near-vertical lines, and K rises through T
// there (the clockwise tangent of K turns up from T's); by the ordering of contacts K - T
// changes sign once on T's piece, so such a point is the crossing. Otherwise: nothing, and
// `crossing` decides.
std::optional<Point2> quickCrossing(const Capsule& t, const Capsule& k, double lo, double hi) {
  if (t.vertical || k.vertical) return std::nullopt;
  constexpr double kMaxSlope = 1e6;  // steeper lines: x no longer places points well
  const bool tLineOk = std::abs(t.b.z - t.a.z) <= kMaxSlope * (t.b.x - t.a.x);
  const bool kLineOk = std::abs(k.b.z - k.a.z) <= kMaxSlope * (k.b.x - k.a.x);
  auto tangent = [](const Capsule& c, const Feature& f, const Point2& q) {
    if (!f.isArc) return Point2{c.b.x - c.a.x, c.b.z - c.a.z};
    return Point2{q.z - f.point.z, f.point.x - q.x};  // clockwise along the upper arc
  };
  // In order of frequency on random walks: a peak of T (its start a: the arc around a
  // vertex belongs to the later of its two edges) meets a peak of K, then slopes.
  constexpr std::array<std::pair<Stretch, Stretch>, 6> kPairs{{{Stretch::arcA, Stretch::arcB},
                                                               {Stretch::arcA, Stretch::arcA},
                                                               {Stretch::line, Stretch::arcB},
                                                               {Stretch::line, Stretch::arcA},
                                                               {Stretch::arcA, Stretch::line},
                                                               {Stretch::line, Stretch::line}}};
  for (const auto& [ts, ks] : kPairs) {
    if ((ts == Stretch::line && !tLineOk) || (ks == Stretch::line && !kLineOk)) continue;
    const Feature f = featureOf(t, ts);
    const Feature g = featureOf(k, ks);
    if (f.isArc && g.isArc && f.point == g.point) continue;
    std::array<Point2, 2> roots{};
    const int n = featureRoots(f, g, t.r, roots);
    for (int i = 0; i < n; ++i) {
      const Point2& q = roots[i];
      const double margin = xMargin(t, q) + 1e-9 * (hi - lo);
      if (!(q.x > lo + margin && q.x < hi - margin)) continue;
      if (stretchOf(t, q) != ts || stretchOf(k, q) != ks) continue;
      const Point2 u = tangent(t, f, q);
      const Point2 w = tangent(k, g, q);
      // turn > 1e-9 |u| |w|, squared (no square roots).
      const double turn = u.x * w.z - u.z * w.x;
      if (turn > 0.0 && turn * turn > 1e-18 * (u.x * u.x + u.z * u.z) * (w.x * w.x + w.z * w.z)) {
        return q;
      }
    }
  }
  return std::nullopt;
}

// The slope-slope hand-over at a concave vertex shared by T (ending there) and K (starting
// there), Figure 6a: the offset lines meet at v + r (n_T + n_K) / (1 + n_T . n_K), the centre
// at distance r from both lines. It is the hand-over if it lies on both offset lines' segments
// (tested by projection, which a near-vertical line's x range cannot do) and not left of
// `from`, where T's piece starts; otherwise nothing.
std::optional<Point2> slopeSlopeHandOver(const Capsule& t, const Capsule& k, double from) {
  const double denom = 1.0 + t.nx * k.nx + t.nz * k.nz;
  if (!(denom > 1e-8)) return std::nullopt;
  const Point2 q{t.b.x + t.r * (t.nx + k.nx) / denom, t.b.z + t.r * (t.nz + k.nz) / denom};
  const double tT = projectOnLine(t, q);
  const double tK = projectOnLine(k, q);
  if (q.x >= from && tT >= 0.0 && tT <= 1.0 && tK >= 0.0 && tK <= 1.0) return q;
  return std::nullopt;
}

struct StackEntry {
  std::size_t edge = 0;
  double x = 0.0;   // where this edge's capsule takes over the envelope
  double z = 0.0;   // the capsule's top there
  double nx = 0.0;  // the edge's upward unit normal, kept to avoid recomputing it
  double nz = 0.0;
  bool jump = false;  // the envelope jumps there (the ball slides along a vertical edge)
};

// Backward exclusion's test: does capsule K cover the whole piece of `top`, which starts at
// (top.x, top.z) and ends at pieceEnd? By the ordering of contacts it does when it is on or
// above that piece's start. At the start this is "the point is within r of K's edge" (no
// square root). When the point is on K's boundary up to rounding (within `band`), the
// distance cannot tell, and two circles touching at their extremes may still part by far
// more than the rounding (one a little above the other): then compare heights a little to
// the right, inside the piece, where the order that holds from there on shows.
bool dominatesPiece(const Capsule& K, const StackEntry& top, std::span<const Point2> chain,
                    double r, double band, double pieceEnd) {
  const int side = sideOfCapsule({top.x, top.z}, K.a, K.b, r, band);
  if (side != 0) return side < 0;
  const Capsule T = capsuleWithNormal(chain[top.edge], chain[top.edge + 1], r, top.nx, top.nz);
  const double x = top.x + 1e-6 * std::max(0.0, std::min(pieceEnd, T.right()) - top.x);
  if (x < K.left() || x > K.right()) return false;
  return K.top(x) >= T.top(x);
}

void exactStep(std::span<const Point2> chain, std::size_t k, double r, double tau, double band,
               double verticalRun, std::vector<StackEntry>& stack, HullStats& stats);

// The filtered pass: the same stack of capsules, built on "units" (README, Performance).
//
// A unit is an edge's offset line followed by the arc around its end vertex (unit -1: the arc
// around v_0 alone), so that every vertex arc is in exactly one unit and a unit's top is one
// line and one arc. By the ordering of contacts (scallop_hull.hpp) units appear along the
// envelope in chain order, each on one interval, and a new unit U_k takes over from one
// crossing onward: it covers a stacked unit's piece when that piece's start P lies right of
// U_k's first point s0 and within r of edge k (P is on the envelope, above the capsule's lower
// boundary, so inside the capsule means below its top, which right of s0 is U_k's). Which
// pair of stretches crosses is read from at most two side tests at the units' junctions, and
// only that pair is solved, with featureRoots and the very features the exact pass gives it,
// so that each crossing comes out bit for bit as that pass computes it.
//
// The units are written out as the exact pass's capsule stack: a unit's line belongs to its
// edge's capsule; its arc to the next edge's capsule once that capsule has taken over at the
// convex vertex (the exact pass gives a vertex arc to the later of its two edges then, and
// keeps that capsule while its start is not covered, even when the next unit's is), and to
// its own capsule otherwise. A unit's entries are written when the next unit, which ends its
// piece, is pushed.
//
// An edge the filters cannot decide (a vertical edge, a tie within rounding that a side test
// cannot tell, a crossing not found on the one pair, a crossing with what lies below the
// units) is handed to the exact pass: the capsule stack is completed and exactStep adds the
// edge. The units start again above what the exact pass built once its top is a capsule that
// starts on its own line or end arc and does not jump; until then the next edges go to the
// exact pass too. The decisions the filtered pass does take are the exact pass's but at ties
// within rounding, which the two may break differently (the exact pass compares the tops a
// little to the right of a piece's start, which can land where two capsules share a vertex
// arc, past a line piece shorter than that step); tests/paths/scallop_hull_test.cpp compares
// the two bit for bit and, where they differ, within the tolerance.
class UnitPass {
 public:
  UnitPass(std::span<const Point2> chain, double r, double tau, double band, double verticalRun)
      : chain_(chain), v_(chain.data()), r_(r), tau_(tau), band_(band), verticalRun_(verticalRun) {}

  std::vector<StackEntry> run(HullStats& stats) {
    std::vector<StackEntry> capsules;
    capsules_ = &capsules;
    stats_ = &stats;
    units_.reserve(std::min<std::size_t>(chain_.size(), std::size_t{1} << 20));
    units_.push_back({kBottom, 0.0, 0.0, 0.0, 1.0});
    units_.push_back({-1, v_[0].x - r_, v_[0].z, 0.0, 1.0});
    for (long k = 0; k + 1 < static_cast<long>(chain_.size()); ++k) {
      if (units_.size() > 1 && addUnit(k)) continue;
      handToExactPass(k);
    }
    writeCapsules();
    return capsules;
  }

 private:
  static constexpr long kBottom = -2;  // the unit below all others: what the exact pass built

  struct Unit {
    long edge;      // -1: the arc around v_0; e >= 0: edge e's offset line, then the arc around v_{e+1}
    double x, z;    // where the unit takes over the envelope
    double nx, nz;  // edge e's upward unit normal (makeCapsule's)
    bool afterArc = false;  // the unit below ends its piece here on its arc (else on its line)
    bool handed = false;    // its arc went to the next edge's capsule (at a convex vertex)
  };

  [[nodiscard]] double lineEndX(const Unit& u) const { return v_[u.edge + 1].x + r_ * u.nx; }
  [[nodiscard]] Feature lineFeature(long edge, double nx, double nz) const {
    const Point2& a = v_[edge];
    const Point2& b = v_[edge + 1];
    return {false, {a.x + r_ * nx, a.z + r_ * nz}, b.x - a.x, b.z - a.z};
  }
  [[nodiscard]] Feature arcFeature(long vertex) const { return {true, v_[vertex], 0.0, 0.0}; }

  // The unit's top at x (its line, else its arc; -infinity outside its reach).
  [[nodiscard]] double top(const Unit& u, double x) const {
    const Point2& c = v_[u.edge + 1];
    if (u.edge >= 0) {
      const Point2& a = v_[u.edge];
      if (x < a.x + r_ * u.nx) return -std::numeric_limits<double>::infinity();
      if (x <= c.x + r_ * u.nx) return capsuleWithNormal(a, c, r_, u.nx, u.nz).top(x);
    }
    if (std::abs(x - c.x) > r_) return -std::numeric_limits<double>::infinity();
    return arcTop(c, r_, x);
  }

  // Appends the capsule entries of the units above the bottom, each unit's piece ending where
  // the next one starts (on its arc or its line: the next unit's afterArc) and the last one's
  // at its end, then leaves no units. Each unit is written once, so all the writing is O(n).
  void writeCapsules() {
    std::vector<StackEntry>& capsules = *capsules_;
    // One entry a unit, two where its arc went to the next capsule (a convex vertex); grown
    // geometrically, as a hand-off to the exact pass writes a few units at a time.
    const std::size_t needed = capsules.size() + units_.size() + units_.size() / 4;
    if (needed > capsules.capacity()) capsules.reserve(std::max(needed, 2 * capsules.capacity()));
    bool continues = false;  // the unit's line continues the entry the unit below wrote
    for (std::size_t i = 1; i < units_.size(); ++i) {
      const Unit& u = units_[i];
      const bool last = i + 1 == units_.size();
      const long nextEdge = last ? -1 : units_[i + 1].edge;
      const bool endsOnArc = last || units_[i + 1].afterArc;
      if (u.edge < 0) {
        // The arc around v_0 starts capsule 0 (edge 0 is not vertical: the unit pass took
        // it); the next unit continues it if it is unit 0.
        const UnitNormal first = upwardNormal(v_[0], v_[1]);
        capsules.push_back({0, u.x, u.z, first.nx, first.nz, false});
        continues = nextEdge == 0;
        continue;
      }
      const std::size_t edge = static_cast<std::size_t>(u.edge);
      const double s1 = lineEndX(u);
      const bool hasLine = u.x < s1;
      if (hasLine && !continues) capsules.push_back({edge, u.x, u.z, u.nx, u.nz, false});
      const bool wasContinued = continues;
      continues = false;
      if (endsOnArc && u.handed) {
        // The arc around v_{e+1} is the next capsule's, from where the line ends.
        const UnitNormal next = upwardNormal(v_[u.edge + 1], v_[u.edge + 2]);
        if (hasLine) {
          capsules.push_back({edge + 1, s1, v_[u.edge + 1].z + r_ * u.nz, next.nx, next.nz, false});
        } else {
          capsules.push_back({edge + 1, u.x, u.z, next.nx, next.nz, false});
        }
        continues = nextEdge == u.edge + 1;
      } else if (!hasLine && !wasContinued) {
        capsules.push_back({edge, u.x, u.z, u.nx, u.nz, false});
      }
    }
    units_.clear();
  }

  // Pops `pops` units, then pushes unit k at (x, z), ending the piece of the unit below on
  // its arc or its line.
  void commit(std::size_t pops, long k, double x, double z, const UnitNormal& K, bool topEndsOnArc) {
    units_.erase(units_.end() - static_cast<std::ptrdiff_t>(pops), units_.end());
    stats_->pops += pops;
    units_.push_back({k, x, z, K.nx, K.nz, topEndsOnArc, false});
    ++stats_->pushes;
  }

  // The edge goes to the exact pass; the units start again above its stack when they can.
  void handToExactPass(long k) {
    // The stack as the exact pass has it after edge k-1 (before edge 0 it is empty: the arc
    // around v_0 is capsule 0's, which exactStep adds).
    if (units_.size() == 2 && units_[1].edge < 0) units_.clear();
    writeCapsules();
    const std::size_t edge = static_cast<std::size_t>(k);
    exactStep(chain_, edge, r_, tau_, band_, verticalRun_, *capsules_, *stats_);
    ++stats_->exactSteps;
    const StackEntry top = capsules_->back();
    if (top.edge != edge || top.jump) return;
    const Capsule K = makeCapsule(v_[k], v_[k + 1], r_, verticalRun_);
    if (K.vertical || stretchOf(K, {top.x, top.z}) == Stretch::arcA) return;
    // Unit k takes that capsule's place (writeCapsules writes it back as it was).
    capsules_->pop_back();
    units_.push_back({kBottom, 0.0, 0.0, 0.0, 1.0});
    units_.push_back({k, top.x, top.z, K.nx, K.nz});
  }

  // Adds unit k when the filters decide every step; false (nothing changed) otherwise.
  bool addUnit(long k) {
    const Point2& a = v_[k];
    const Point2& b = v_[k + 1];
    if (!(b.x - a.x > verticalRun_)) return false;  // vertical (makeCapsule's test)
    const UnitNormal K = upwardNormal(a, b);  // makeCapsule's, without the rest of the capsule
    const double s0 = a.x + r_ * K.nx;
    const double s1 = b.x + r_ * K.nx;

    // Backward exclusion, decided before anything changes.
    std::size_t pops = 0;
    double pieceEnd = 0.0;  // the top unit's piece ends at the last popped start
    while (true) {
      const Unit& t = units_[units_.size() - 1 - pops];
      if (t.edge == kBottom) return false;
      ++stats_->comparisons;
      if (t.x < s0) break;
      int side = sideOfCapsule({t.x, t.z}, a, b, r_, band_);
      if (side == 0) {
        // Too close to tell (a contact shared within rounding): compare the tops a little to
        // the right, inside the piece, as dominatesPiece does.
        const double end = pops > 0 ? pieceEnd : v_[t.edge + 1].x + r_;
        const double x = t.x + 1e-6 * std::max(0.0, end - t.x);
        if (x > b.x + r_) return false;
        side = capsuleWithNormal(a, b, r_, K.nx, K.nz).top(x) >= top(t, x) ? -1 : 1;
      }
      if (side > 0) break;
      pieceEnd = t.x;
      ++pops;
    }
    const Unit& t = units_[units_.size() - 1 - pops];
    if (t.edge == kBottom) return false;

    if (pops == 0) {
      // The top is unit k-1, whose arc around a = v_k ends the envelope so far.
      if (t.edge != k - 1) return false;
      if (k == 0) {
        commit(0, k, s0, a.z + r_ * K.nz, K, true);
        return true;
      }
      const Point2& p = v_[k - 1];
      const double turn = (a.x - p.x) * (b.z - a.z) - (a.z - p.z) * (b.x - a.x);
      if (turn <= 0.0) {
        // Convex at v_k: the new line leaves the arc around v_k at its tangent point, and the
        // arc is capsule k's.
        if (!(s0 > t.x)) return false;
        units_.back().handed = true;
        commit(0, k, s0, a.z + r_ * K.nz, K, true);
        return true;
      }
      // Concave at v_k: the exact pass's slope-slope closed form.
      if (const auto q = slopeSlopeHandOver(capsuleWithNormal(p, a, r_, t.nx, t.nz),
                                            capsuleWithNormal(a, b, r_, K.nx, K.nz), t.x)) {
        commit(0, k, q->x, q->z, K, false);
        return true;
      }
      pieceEnd = a.x + r_;  // otherwise the crossing below, over the top's whole piece
    }

    // The crossing of U_k with the top unit U_j on its piece (t.x, pieceEnd).
    const long j = t.edge;
    const double topS1 = j >= 0 ? lineEndX(t) : -std::numeric_limits<double>::infinity();
    bool topOnLine = j >= 0 && t.x < topS1;
    if (topOnLine && topS1 < pieceEnd) {
      // The top's junction (its line's end) is on the envelope: inside capsule k, the
      // crossing is before it, on the top's line.
      if (topS1 < s0) {
        topOnLine = false;
      } else {
        const int side = sideOfCapsule({topS1, v_[j + 1].z + r_ * t.nz}, a, b, r_, band_);
        if (side == 0) return false;
        topOnLine = side < 0;
      }
    }
    // The new unit's stretch: its line if U_k is above the top's stretch where that line
    // ends (the crossing is then left of it), else its arc around b.
    bool newOnLine = true;
    if (s1 <= t.x) {
      newOnLine = false;
    } else if (s1 < pieceEnd) {
      const Point2 junction{s1, b.z + r_ * K.nz};
      const Point2& c = v_[j + 1];
      double side;
      double sideBand;
      if (topOnLine) {
        const Point2& p = v_[j];
        side = (junction.z - (c.z + r_ * t.nz)) * (c.x - p.x) - (junction.x - topS1) * (c.z - p.z);
        sideBand = 4.0 * band_ * (std::abs(c.x - p.x) + std::abs(c.z - p.z));
      } else {
        const double ux = junction.x - c.x;
        const double uz = junction.z - c.z;
        side = std::abs(ux) > r_ ? 1.0 : circleExcess(ux, uz, r_);
        sideBand = 4.0 * r_ * band_;
      }
      if (std::abs(side) <= sideBand) return false;
      newOnLine = side > 0.0;
    }
    const Feature f = topOnLine ? lineFeature(j, t.nx, t.nz) : arcFeature(j + 1);
    const Feature g = newOnLine ? lineFeature(k, K.nx, K.nz) : arcFeature(k + 1);
    if (f.isArc && g.isArc && f.point == g.point) return false;
    std::array<Point2, 2> roots{};
    const int count = featureRoots(f, g, r_, roots);
    // The one root on both stretches, inside the piece, where U_k rises through the top.
    int found = -1;
    for (int i = 0; i < count; ++i) {
      const Point2& q = roots[i];
      const double margin = 32.0 * std::numeric_limits<double>::epsilon() * (r_ + std::abs(q.x));
      if (!(q.x > t.x + margin && q.x < pieceEnd - margin)) continue;
      if (newOnLine ? !(q.x > s0 + margin && q.x < s1 - margin) : !(q.x > s1 + margin)) continue;
      if (topOnLine ? !(q.x < topS1 - margin) : !(q.x > topS1 + margin)) continue;
      // Rising: the clockwise tangent of U_k turns up from the top's (quickCrossing's test).
      const Point2 u = f.isArc ? Point2{q.z - f.point.z, f.point.x - q.x} : Point2{f.dx, f.dz};
      const Point2 w = g.isArc ? Point2{q.z - g.point.z, g.point.x - q.x} : Point2{g.dx, g.dz};
      const double turn = u.x * w.z - u.z * w.x;
      if (!(turn > 0.0 && turn * turn > 1e-18 * (u.x * u.x + u.z * u.z) * (w.x * w.x + w.z * w.z))) continue;
      if (found >= 0) return false;  // two: a tangency the exact pass must settle
      found = i;
    }
    if (found < 0) return false;
    const Point2 q = roots[static_cast<std::size_t>(found)];
    commit(pops, k, q.x, q.z, K, !topOnLine);
    return true;
  }

  std::span<const Point2> chain_;
  const Point2* v_;
  double r_;
  double tau_;
  double band_;
  double verticalRun_;
  std::vector<Unit> units_;
  std::vector<StackEntry>* capsules_ = nullptr;
  HullStats* stats_ = nullptr;
};

// Builds the tool path and the hull from the envelope: the stack lists the capsules that
// form c(x), each from its start to the next one's start.
HullElement pointHull(std::span<const Point2> chain) {
  HullElement link;
  link.kind = HullElementKind::link;
  link.start = chain.front();
  link.end = chain.back();
  link.edge = 0;
  return link;
}

class OutputBuilder {
 public:
  OutputBuilder(std::span<const Point2> chain, double r, double tau, ScallopHull& out)
      : chain_(chain), r_(r), tau_(tau), out_(out) {}

  void build(const std::vector<StackEntry>& stack) {
    const Point2 first = chain_.front();
    const Point2 last = chain_.back();
    end_ = {first.x - r_, first.z};
    contact_ = first;
    std::size_t previousEdge = 0;
    for (std::size_t i = 0; i < stack.size(); ++i) {
      const StackEntry& entry = stack[i];
      const Capsule c =
          capsuleWithNormal(chain_[entry.edge], chain_[entry.edge + 1], r_, entry.nx, entry.nz);
      const double to = i + 1 < stack.size() ? stack[i + 1].x : c.right();
      // A difference in height where one capsule hands over to the next is the ball sliding
      // along a vertical edge (or, at the start, the first edge rising vertically).
      // Elsewhere the two capsules cross, and the path goes on from where it is.
      if (i == 0 || entry.jump) verticalTo(entry.z, i == 0 ? 0 : previousEdge, entry.edge);
      std::optional<Point2> handOver;
      if (i + 1 < stack.size() && !stack[i + 1].jump) handOver = {stack[i + 1].x, stack[i + 1].z};
      emitCapsule(c, entry.edge, std::max(entry.x, end_.x), to, handOver);
      previousEdge = entry.edge;
    }
    // At the end, the ball may still have to slide down a final vertical edge; the path
    // then ends exactly at (x_{n-1} + r, z_{n-1}) (a rounding-level gap is snapped).
    verticalTo(last.z, previousEdge, chain_.size() - 2);
    const Point2 finalPoint{last.x + r_, last.z};
    if (!(end_ == finalPoint)) {
      if (near(end_, finalPoint) && !out_.toolpath.empty()) {
        out_.toolpath.back().end = finalPoint;
        end_ = finalPoint;
      } else {
        lineTo(finalPoint, chain_.size() - 2, contact_, contact_);
      }
    }
    closeWithLid(last);
    // The hull runs exactly from v_0 to v_{n-1} (contacts computed as x -+ r may differ from
    // them by a rounding error).
    if (!out_.hull.empty()) {
      if (near(out_.hull.front().start, first)) out_.hull.front().start = first;
      if (near(out_.hull.back().end, last)) out_.hull.back().end = last;
    }
    // A chain whose points all coincide touches the ball at one point: the hull is that
    // point, a zero-length link, so that it still runs from v_0 to v_{n-1}.
    if (out_.hull.empty()) out_.hull.push_back(pointHull(chain_));
  }

 private:
  [[nodiscard]] bool near(const Point2& p, const Point2& q) const {
    return std::abs(p.x - q.x) <= tau_ && std::abs(p.z - q.z) <= tau_;
  }

  // A lid from the current contact point to `next`, centred at the current path point.
  void closeWithLid(const Point2& next) {
    if (!near(contact_, next)) {
      HullElement lid;
      lid.kind = HullElementKind::lid;
      lid.start = contact_;
      lid.end = next;
      lid.center = end_;
      // Lids that coincide (the same centre, within tau) are one lid (the paper's COINCIDE).
      if (!out_.hull.empty() && out_.hull.back().kind == HullElementKind::lid &&
          near(out_.hull.back().center, end_)) {
        out_.hull.back().end = next;
      } else {
        out_.hull.push_back(lid);
      }
    }
    contact_ = next;
  }

  void addLink(const Point2& from, const Point2& to, std::size_t edge) {
    if (near(from, to)) return;
    if (!out_.hull.empty() && out_.hull.back().kind == HullElementKind::link &&
        out_.hull.back().edge == edge && near(out_.hull.back().end, from)) {
      out_.hull.back().end = to;
      return;
    }
    HullElement link;
    link.kind = HullElementKind::link;
    link.start = from;
    link.end = to;
    link.edge = edge;
    out_.hull.push_back(link);
  }

  // Appends a straight move to `to` whose contact runs from contactFrom to contactTo on
  // edge `edge`.
  void lineTo(const Point2& to, std::size_t edge, const Point2& contactFrom,
              const Point2& contactTo) {
    closeWithLid(contactFrom);
    if (near(end_, to)) return;
    PathElement line;
    line.kind = PathElementKind::line;
    line.start = end_;
    line.end = {std::max(to.x, end_.x), to.z};
    line.feature = edge;
    out_.toolpath.push_back(line);
    end_ = line.end;
    addLink(contactFrom, contactTo, edge);
    contact_ = contactTo;
  }

  void arcTo(const Point2& to, std::size_t vertex) {
    const Point2& centre = chain_[vertex];
    closeWithLid(centre);
    if (near(end_, to)) return;
    if (!out_.toolpath.empty() && out_.toolpath.back().kind == PathElementKind::arc &&
        out_.toolpath.back().center == centre && out_.toolpath.back().end == end_) {
      out_.toolpath.back().end = {std::max(to.x, end_.x), to.z};
      end_ = out_.toolpath.back().end;
      return;
    }
    PathElement arc;
    arc.kind = PathElementKind::arc;
    arc.start = end_;
    arc.end = {std::max(to.x, end_.x), to.z};
    arc.center = centre;
    arc.radius = r_;
    arc.clockwise = true;
    arc.feature = vertex;
    out_.toolpath.push_back(arc);
    end_ = arc.end;
  }

  // Vertical slide from the current path point to height z at the same x: the ball rolls
  // along the vertical edges among fromEdge..toEdge that stand at the wall's abscissa.
  void verticalTo(double z, std::size_t fromEdge, std::size_t toEdge) {
    if (std::abs(z - end_.z) <= tau_) return;
    const bool down = z < end_.z;
    const double wallX = down ? end_.x - r_ : end_.x + r_;
    closeWithLid({wallX, end_.z});
    // The vertical edges at wallX among fromEdge..toEdge, in chain order, each carry the
    // ball on as far as they reach in the slide's direction: one path line and one link
    // per edge, never backwards (a vertical zigzag is climbed once).
    auto progress = [&](double from, double to) { return down ? to < from : to > from; };
    auto clampToSlide = [&](double v) { return down ? std::max(v, z) : std::min(v, z); };
    std::size_t lastWall = fromEdge;
    for (std::size_t e = fromEdge; e <= toEdge && e + 1 < chain_.size(); ++e) {
      const Point2& a = chain_[e];
      const Point2& b = chain_[e + 1];
      if (std::abs(b.x - a.x) > 0.1 * tau_ || std::abs(a.x - wallX) > tau_) continue;
      lastWall = e;
      const double target = clampToSlide(b.z);
      // The edge must hold the current height and lead on in the slide's direction.
      const double low = std::min(a.z, b.z);
      const double high = std::max(a.z, b.z);
      if (!progress(end_.z, target) || end_.z < low - tau_ || end_.z > high + tau_) continue;
      slideTo(target, e, a.x);  // contacts on the wall itself, not at end_.x -+ r
    }
    if (std::abs(z - end_.z) > tau_) slideTo(z, lastWall, wallX);
    end_.z = z;
    if (!out_.toolpath.empty() && out_.toolpath.back().kind == PathElementKind::line &&
        out_.toolpath.back().end.x == end_.x) {
      out_.toolpath.back().end.z = z;  // land exactly on z (a rounding-level remainder)
    }
    contact_ = {wallX, z};
  }

  // One vertical path line from the current point to height z, offsetting vertical edge
  // `edge` at wallX, and its link.
  void slideTo(double z, std::size_t edge, double wallX) {
    PathElement line;
    line.kind = PathElementKind::line;
    line.start = end_;
    line.end = {end_.x, z};
    line.feature = edge;
    out_.toolpath.push_back(line);
    addLink({wallX, end_.z}, {wallX, z}, edge);
    end_ = line.end;
    contact_ = {wallX, z};
  }

  // The pieces of capsule c (edge `edge`) from the current path point to abscissa `to`: arc
  // around a, offset line, arc around b. When the next capsule takes over at `to` without a
  // jump, `handOver` is that point and the last piece ends on it. Which piece a point is on
  // is told by its projection on the offset line, not by its x.
  void emitCapsule(const Capsule& c, std::size_t edge, double from, double to,
                   const std::optional<Point2>& handOver) {
    if (to < from) to = from;
    auto endAt = [&](double x) { return handOver ? *handOver : Point2{x, c.top(x)}; };
    if (c.vertical) {
      arcTo(endAt(to), c.a.z >= c.b.z ? edge : edge + 1);
      return;
    }
    double t1 = 1.0;  // where the piece stops on the line, if it stops there
    Stretch stop = Stretch::arcB;
    if (handOver) {
      stop = stretchOf(c, *handOver);
      t1 = std::clamp(projectOnLine(c, *handOver), 0.0, 1.0);
    } else if (to < c.s0) {
      stop = Stretch::arcA;
    } else if (to < c.s1) {
      stop = Stretch::line;
      t1 = c.lineParameter(to);
    }
    const Stretch begin = stretchOf(c, end_);
    const double t0 = begin == Stretch::arcA ? 0.0 : std::clamp(projectOnLine(c, end_), 0.0, 1.0);
    if (begin == Stretch::arcA) {
      // The arc around a ends where the offset line begins (its tangent point, exactly).
      arcTo(stop == Stretch::arcA ? endAt(to) : c.linePoint(0.0), edge);
    }
    if (stop == Stretch::arcA) return;
    if (stop == Stretch::line && begin == Stretch::arcB) return;  // rounding: nothing left
    if (t1 > t0 && t0 < 1.0) {
      auto onEdge = [&](double t) {
        if (t <= 0.0) return c.a;
        if (t >= 1.0) return c.b;
        return Point2{c.a.x + t * (c.b.x - c.a.x), c.a.z + t * (c.b.z - c.a.z)};
      };
      Point2 pathEnd = c.linePoint(1.0);
      if (stop == Stretch::line) pathEnd = handOver ? *handOver : Point2{to, c.linePoint(t1).z};
      lineTo(pathEnd, edge, onEdge(t0), onEdge(t1));
    }
    if (stop == Stretch::arcB) arcTo(endAt(to), edge + 1);
  }

  std::span<const Point2> chain_;
  double r_;
  double tau_;
  ScallopHull& out_;
  Point2 end_;      // current end of the tool path
  Point2 contact_;  // current contact point on the chain
};

// One step of the exact pass: capsule k added to the stack (scallop_hull.hpp, Method), every
// case decided, with vertical edges and ties within rounding.
void exactStep(std::span<const Point2> chain, std::size_t k, double r, double tau, double band,
               double verticalRun, std::vector<StackEntry>& stack, HullStats& stats) {
  auto push = [&](std::size_t edge, double x, double z, const Capsule& c, bool jump = false) {
    stack.push_back({edge, x, z, c.nx, c.nz, jump});
    ++stats.pushes;
  };
  const Capsule K = makeCapsule(chain[k], chain[k + 1], r, verticalRun);
  // Backward exclusion: K covers the whole piece of the top capsule when it is on or above
  // it where that piece starts (contacts are ordered, so K stays above from there on).
  double poppedFrom = K.left();
  bool poppedJump = false;
  const std::size_t entriesBeforePops = stack.size() + 1;
  while (!stack.empty()) {
    const StackEntry& top = stack.back();
    ++stats.comparisons;
    if (!dominatesPiece(K, stack.back(), chain, r, band,
                        stack.size() + 1 == entriesBeforePops ? K.right() : poppedFrom)) {
      break;
    }
    poppedFrom = top.x;
    poppedJump = top.jump;
    stack.pop_back();
    ++stats.pops;
  }
  if (stack.empty()) {
    push(k, poppedFrom, K.top(poppedFrom), K);
    return;
  }
  const StackEntry& top = stack.back();
  const Capsule T =
      capsuleWithNormal(chain[top.edge], chain[top.edge + 1], r, top.nx, top.nz);
  const double hi = T.right();
  const double lo = std::min(std::max(top.x, K.left()), hi);
  ++stats.comparisons;
  if (top.edge + 1 == k && !T.vertical && !K.vertical) {
    // Adjacent edges meeting at v = chain[k]: K's capsule holds the disk around v, so K is
    // above T where T ends, and the hand-over is known in closed form.
    const double turn =
        (T.b.x - T.a.x) * (K.b.z - K.a.z) - (T.b.z - T.a.z) * (K.b.x - K.a.x);
    if (turn <= 0.0) {
      // Convex (or straight) at v: both capsules are the arc around v between the two
      // offset lines, so K takes over where T's offset line ends.
      if (T.s1 >= lo && T.s1 <= hi) {
        push(k, T.s1, T.b.z + r * T.nz, K);
      } else {
        const double start = std::clamp(T.s1, lo, hi);
        push(k, start, K.top(start), K);
      }
      return;
    }
    // Concave at v: the slope-slope hand-over, when it lies on both offset lines.
    if (const auto q = slopeSlopeHandOver(T, K, lo)) {
      push(k, q->x, q->z, K);
      return;
    }
  } else if (!isBelowTop(K, hi, T.upperEndAtRight().z)) {
    // K is below T where T ends: it takes over only beyond T's reach (the ball drops
    // along a vertical edge there), or never.
    if (K.right() > hi) push(k, hi, K.top(hi), K, true);
    return;
  }
  const std::optional<Point2> quick = quickCrossing(T, K, lo, hi);
  const Point2 handOver =
      quick ? *quick
            : crossing(T, K, lo, hi, lo == top.x ? top.z : T.top(lo), T.upperEndAtRight().z);
  const double start = handOver.x;
  // Taking over where K begins, K may start above T: the ball climbs a vertical edge (K's
  // own, or one K has just covered). Taking over where T began, T's piece is empty and K
  // inherits its hand-over; likewise where a popped piece began.
  // (Equal up to rounding: the abscissae come from different sums.)
  const double margin = xMargin(K, handOver);
  const bool jump = (start <= K.left() + margin && K.top(start) > handOver.z + tau) ||
                    (std::abs(start - top.x) <= margin && top.jump) ||
                    (std::abs(start - poppedFrom) <= margin && poppedJump);
  // After a jump the piece starts at K's own height there; otherwise at the crossing
  // point, computed on the curves themselves (well conditioned on a near-vertical line).
  push(k, start, jump ? K.top(start) : handOver.z, K, jump);
}

// The exact pass alone over the whole chain.
std::vector<StackEntry> exactPass(std::span<const Point2> chain, double r, double tau, double band,
                                  double verticalRun, HullStats& stats) {
  std::vector<StackEntry> stack;
  stack.reserve(std::min<std::size_t>(chain.size(), std::size_t{1} << 20));
  for (std::size_t k = 0; k + 1 < chain.size(); ++k) {
    exactStep(chain, k, r, tau, band, verticalRun, stack, stats);
    ++stats.exactSteps;
  }
  return stack;
}

std::vector<std::size_t> monotoneUpperHull(std::span<const Point2> chain, HullStats& stats) {
  // Andrew's monotone chain over points already ordered by x. Ties in x (vertical edges)
  // and repeated points need care: the turn test must compare a vertex with the last
  // *distinct* vertex before it, or a repeated point would block every later pop. Each
  // kept vertex records where its run of repeats starts, so that lookup is O(1).
  struct Kept {
    std::size_t index;
    std::size_t runStart;  // position in `kept` of the first vertex equal to this one
  };
  std::vector<Kept> kept;
  kept.reserve(std::min<std::size_t>(chain.size(), std::size_t{1} << 16));
  for (std::size_t i = 0; i < chain.size(); ++i) {
    const Point2& p = chain[i];
    while (!kept.empty()) {
      const Kept& last = kept.back();
      if (last.runStart == 0) break;  // nothing distinct before it
      const Point2& b = chain[last.index];
      const Point2& a = chain[kept[last.runStart - 1].index];
      const double cross = (b.x - a.x) * (p.z - a.z) - (b.z - a.z) * (p.x - a.x);
      // Pop b (with its repeats) when it lies strictly below the segment a-p, or when it
      // is collinear but not between a and p (a reversal along a vertical edge). Collinear
      // vertices between a and p stay: the chain touches the hull there.
      const double along = (b.x - a.x) * (p.x - b.x) + (b.z - a.z) * (p.z - b.z);
      ++stats.comparisons;
      if (cross > 0.0 || (cross == 0.0 && along < 0.0)) {
        stats.pops += kept.size() - last.runStart;
        kept.resize(last.runStart);
      } else {
        break;
      }
    }
    const std::size_t position = kept.size();
    const bool repeat = !kept.empty() && chain[kept.back().index] == p;
    kept.push_back({i, repeat ? kept.back().runStart : position});
    if (i > 0) ++stats.pushes;  // v_i closes edge e_{i-1}: one push per edge
  }
  std::vector<std::size_t> hull;
  hull.reserve(kept.size());
  for (const Kept& k : kept) hull.push_back(k.index);
  return hull;
}

void hullForInfiniteRadius(std::span<const Point2> chain, ScallopHull& out) {
  const std::vector<std::size_t> vertices = monotoneUpperHull(chain, out.stats);
  for (std::size_t i = 0; i + 1 < vertices.size(); ++i) {
    const std::size_t a = vertices[i];
    const std::size_t b = vertices[i + 1];
    if (chain[a] == chain[b]) continue;
    HullElement element;
    element.start = chain[a];
    element.end = chain[b];
    if (b == a + 1) {
      element.kind = HullElementKind::link;
      element.edge = a;
    } else {
      element.kind = HullElementKind::lid;
      element.straight = true;
    }
    out.hull.push_back(element);
  }
  if (out.hull.empty()) out.hull.push_back(pointHull(chain));
}

}  // namespace

std::vector<std::size_t> upperHullIndices(std::span<const Point2> chain) {
  HullStats unused;
  return monotoneUpperHull(chain, unused);
}

ScallopHull scallopHull(std::span<const Point2> chain, double radius, HullMethod method) {
  validateChain(chain);
  if (!(radius > 0.0)) {
    throw Error(fmt::format("the radius must be a positive number, got {}", radius));
  }
  ScallopHull out;
  out.radius = radius;
  if (std::isinf(radius)) {
    hullForInfiniteRadius(chain, out);
    return out;
  }
  const double r = radius;
  const double scale = std::max(r, coordinateScale(chain));
  const double tau = kRelativeTolerance * scale;
  // Far from the origin the tolerance outgrows the ball: the hull would be answered within
  // more than r / 1000 (at 1e15 with r = 1, within 1000: an empty path). Refused instead.
  if (tau > kMaxToleranceOfRadius * r)
    throw Error(fmt::format("the radius {} is below {} of the chain's largest |coordinate| {}: the tolerance "
                            "{} x {} would exceed {} of the radius; give the chain's coordinates from a nearby origin",
                            r, kRelativeTolerance / kMaxToleranceOfRadius, scale, kRelativeTolerance, scale,
                            kMaxToleranceOfRadius));
  // Edges steeper than this run are vertical (a tenth of the tolerance; see makeCapsule).
  const double verticalRun = 0.1 * tau;
  // Distances are known to about this much (a few ulps of the coordinates and of r).
  const double band = 64.0 * std::numeric_limits<double>::epsilon() * (scale + r);

  const std::vector<StackEntry> stack =
      method == HullMethod::automatic ? UnitPass(chain, r, tau, band, verticalRun).run(out.stats)
                                      : exactPass(chain, r, tau, band, verticalRun, out.stats);
  // About 1.25 path and 1.13 hull elements per stack entry on random walks; more grow the
  // vectors once. (Twice the entries, as before, put 2^20-edge results over glibc's mmap
  // threshold: new pages, faulted in, at every call.)
  out.toolpath.reserve(stack.size() + stack.size() / 2 + 8);
  out.hull.reserve(stack.size() + stack.size() / 2 + 8);
  OutputBuilder(chain, r, tau, out).build(stack);
  return out;
}

double pathHeightAt(std::span<const PathElement> toolpath, double x) {
  // Elements are ordered with non-decreasing x, so those whose x range holds x are
  // contiguous: find the first that ends at or after x.
  auto it = std::lower_bound(toolpath.begin(), toolpath.end(), x,
                             [](const PathElement& e, double value) { return e.end.x < value; });
  double best = -std::numeric_limits<double>::infinity();
  for (; it != toolpath.end() && it->start.x <= x; ++it) {
    const PathElement& e = *it;
    double z;
    if (e.kind == PathElementKind::arc) {
      z = arcTop(e.center, e.radius, x);
    } else if (e.end.x == e.start.x) {
      z = std::max(e.start.z, e.end.z);
    } else {
      const double t = (x - e.start.x) / (e.end.x - e.start.x);
      z = e.start.z + t * (e.end.z - e.start.z);
    }
    best = std::max(best, z);
  }
  return best;
}

double pathLength(std::span<const PathElement> toolpath) {
  double length = 0.0;
  for (const PathElement& e : toolpath) {
    if (e.kind == PathElementKind::line) {
      length += std::hypot(e.end.x - e.start.x, e.end.z - e.start.z);
    } else {
      const double a0 = std::atan2(e.start.z - e.center.z, e.start.x - e.center.x);
      const double a1 = std::atan2(e.end.z - e.center.z, e.end.x - e.center.x);
      double sweep = e.clockwise ? a0 - a1 : a1 - a0;
      if (sweep < 0.0) sweep += 2.0 * std::numbers::pi;
      length += e.radius * sweep;
    }
  }
  return length;
}

}  // namespace scallop
