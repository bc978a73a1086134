#include "scallop/paths/section.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include <fmt/format.h>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"

namespace scallop {
namespace {

using Piece = std::vector<SectionPoint>;

// f(u, v) = n . r(u, v) - d on one patch (times w on a rational patch), with its partial derivatives and the roots of f
// along every iso-parameter line a cell edge lies on. The roots are computed once per line
// (not per cell), so the two cells that share an edge see the same crossings bit for bit,
// and the pieces traced in them meet exactly.
class PatchSection {
 public:
  PatchSection(const BezierPatch& patch, std::size_t index, const Vec3& n, double d)
      : patch_(patch), index_(index) {
    f_.degreeU = patch.degreeU;
    f_.degreeV = patch.degreeV;
    f_.coefficients.reserve(patch.control.size());
    // A rational patch: f w = n . X - d w (X = w r, bezier.hpp's homogeneous coordinates) is
    // a polynomial with coefficients w_jk (n . p_jk - d), and has f's zeros and signs (w > 0).
    for (std::size_t i = 0; i < patch.control.size(); ++i)
      f_.coefficients.push_back((patch.rational() ? patch.weights[i] : 1.0) * (dot(n, patch.control[i]) - d));
    fu_ = derivativeU(f_);
    fv_ = derivativeV(f_);
  }

  const Bernstein2& f() const { return f_; }
  const Bernstein2& fu() const { return fu_; }
  const Bernstein2& fv() const { return fv_; }

  double value(double u, double v) const { return evaluate(f_, u, v); }

  SectionPoint at(double u, double v) const { return {point(patch_, u, v), index_, u, v}; }

  /// Roots of f along the line u = u0 (as values of v), or along v = v0 (values of u),
  /// sorted, each once.
  const std::vector<double>& rootsAlongU(double u0) { return roots(u0, true); }
  const std::vector<double>& rootsAlongV(double v0) { return roots(v0, false); }

 private:
  const std::vector<double>& roots(double at, bool alongU) {
    auto& cache = alongU ? rootsAlongU_ : rootsAlongV_;
    auto found = cache.find(at);
    if (found != cache.end()) return found->second;
    const Bernstein1 line = alongU ? isoU(f_, at) : isoV(f_, at);
    std::vector<double> result;
    // A boundary or iso line lying in the plane (f vanishes identically on it) contributes
    // no isolated crossings; the cells on both sides still see f's sign change across it
    // through their interiors only if the surface crosses the plane there.
    if (!isZero(line)) {
      result = realRoots(line);
      result.erase(std::unique(result.begin(), result.end()), result.end());
    }
    return cache.emplace(at, std::move(result)).first->second;
  }

  const BezierPatch& patch_;
  std::size_t index_;
  Bernstein2 f_, fu_, fv_;
  std::map<double, std::vector<double>> rootsAlongU_, rootsAlongV_;
};

struct Cell {
  double u0, u1, v0, v1;
  int depth;
};

double distanceToSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = dot(ab, ab);
  double t = len2 > 0.0 ? dot(p - a, ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return norm(p - (a + t * ab));
}

// Traces the zero set in a simple cell, where f is strictly monotone in the "t" parameter
// (v when !swap, u when swap). In (s, t) coordinates the zero set is a graph t = g(s).
class GraphTracer {
 public:
  GraphTracer(PatchSection& section, const Cell& cell, bool swap, double tolerance)
      : section_(section), swap_(swap), tolerance_(tolerance) {
    s0_ = swap ? cell.v0 : cell.u0;
    s1_ = swap ? cell.v1 : cell.u1;
    t0_ = swap ? cell.u0 : cell.v0;
    t1_ = swap ? cell.u1 : cell.v1;
  }

  void trace(std::vector<Piece>& pieces) {
    // Roots of f on the edges t = t0 and t = t1 split [s0, s1] into intervals over each of
    // which f(s, t0) and f(s, t1) keep their signs: a piece of the graph spans an interval
    // exactly when the signs differ (f monotone in t has then one zero on [t0, t1]).
    const std::vector<double> low = edgeRoots(t0_);
    const std::vector<double> high = edgeRoots(t1_);
    std::vector<double> breaks{s0_, s1_};
    breaks.insert(breaks.end(), low.begin(), low.end());
    breaks.insert(breaks.end(), high.begin(), high.end());
    std::sort(breaks.begin(), breaks.end());
    breaks.erase(std::unique(breaks.begin(), breaks.end()), breaks.end());
    for (std::size_t i = 0; i + 1 < breaks.size(); ++i) {
      const double a = breaks[i];
      const double b = breaks[i + 1];
      const double mid = 0.5 * (a + b);
      const double fl = F(mid, t0_);
      const double fh = F(mid, t1_);
      if (!((fl < 0.0 && fh > 0.0) || (fl > 0.0 && fh < 0.0))) continue;
      Piece piece;
      const SectionPoint start = endPoint(a, low, high);
      const SectionPoint end = endPoint(b, low, high);
      piece.push_back(start);
      refine(a, start, b, end, piece, 0);
      pieces.push_back(std::move(piece));
    }
  }

 private:
  double F(double s, double t) const { return swap_ ? section_.value(t, s) : section_.value(s, t); }
  double Ft(double s, double t) const {
    return swap_ ? evaluate(section_.fu(), t, s) : evaluate(section_.fv(), s, t);
  }
  SectionPoint at(double s, double t) const { return swap_ ? section_.at(t, s) : section_.at(s, t); }

  // Roots along the line t = const, restricted to the open interval (s0, s1).
  std::vector<double> edgeRoots(double t) {
    const std::vector<double>& all = swap_ ? section_.rootsAlongU(t) : section_.rootsAlongV(t);
    std::vector<double> inside;
    for (double s : all)
      if (s > s0_ && s < s1_) inside.push_back(s);
    return inside;
  }

  // The end of a piece at s: on the edge t = t0 or t = t1 when s is a root there, else on
  // the cell's side s = s0 or s1, at the crossing the whole iso line's roots give.
  SectionPoint endPoint(double s, const std::vector<double>& low, const std::vector<double>& high) {
    if (std::binary_search(low.begin(), low.end(), s)) return at(s, t0_);
    if (std::binary_search(high.begin(), high.end(), s)) return at(s, t1_);
    const double solved = solve(s);
    const std::vector<double>& line = swap_ ? section_.rootsAlongV(s) : section_.rootsAlongU(s);
    double best = solved;
    double bestGap = std::numeric_limits<double>::infinity();
    for (double t : line) {
      if (t < t0_ || t > t1_) continue;
      if (std::abs(t - solved) < bestGap) {
        bestGap = std::abs(t - solved);
        best = t;
      }
    }
    return at(s, best);
  }

  // The zero of t -> f(s, t) on [t0, t1]: Newton's method kept inside a shrinking bracket,
  // bisecting whenever a step leaves it. f is monotone in t here, so the bracket holds the
  // one zero; if rounding leaves both ends of one sign, the end nearer zero is returned.
  double solve(double s) const {
    double lo = t0_, hi = t1_;
    double flo = F(s, lo), fhi = F(s, hi);
    if (flo == 0.0) return lo;
    if (fhi == 0.0) return hi;
    if ((flo < 0.0) == (fhi < 0.0)) return std::abs(flo) <= std::abs(fhi) ? lo : hi;
    double t = lo - flo * (hi - lo) / (fhi - flo);
    for (int iteration = 0; iteration < 100; ++iteration) {
      const double ft = F(s, t);
      if (ft == 0.0) return t;
      if ((ft < 0.0) == (flo < 0.0)) {
        lo = t;
        flo = ft;
      } else {
        hi = t;
      }
      if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(t)))
        break;
      const double slope = Ft(s, t);
      double next = slope != 0.0 ? t - ft / slope : 0.5 * (lo + hi);
      if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
      if (next == t) break;
      t = next;
    }
    return t;
  }

  // Appends the vertices after `a` up to and including `b`, splitting [sa, sb] until the
  // curve's points at the quarter parameters lie within the tolerance of the chord.
  void refine(double sa, const SectionPoint& a, double sb, const SectionPoint& b, Piece& piece,
              int depth) {
    const double sm = 0.5 * (sa + sb);
    const SectionPoint m = at(sm, solve(sm));
    if (depth < 48 && sb - sa > 1e-13) {
      double deviation = distanceToSegment(m.point, a.point, b.point);
      if (deviation <= tolerance_) {
        for (double q : {0.25, 0.75}) {
          const double sq = sa + q * (sb - sa);
          deviation = std::max(deviation,
                               distanceToSegment(at(sq, solve(sq)).point, a.point, b.point));
        }
      }
      if (deviation > tolerance_ || depth < 1) {
        refine(sa, a, sm, m, piece, depth + 1);
        refine(sm, m, sb, b, piece, depth + 1);
        return;
      }
    }
    piece.push_back(b);
  }

  PatchSection& section_;
  bool swap_;
  double tolerance_;
  double s0_ = 0.0, s1_ = 1.0, t0_ = 0.0, t1_ = 1.0;
};

// Strict one-signedness of a polynomial's coefficients on a cell (no zero there).
bool oneSigned(const Bernstein2& p) { return !mayVanish(p); }

// True when f's coefficients on a cell are all >= 0 or all <= 0. Then f has no zero in the
// cell's open interior (there every basis function is positive, so f is a positive
// combination of its coefficients, zero only if all are): its zeros, if any, lie on the
// cell's boundary, where the neighbours that cross the plane there find them, or on the
// patch boundary, whose edges lying in the plane are added whole (sectionPatch).
bool cannotCross(const Bernstein2& p) {
  const Bounds b = bounds(p);
  return b.lo >= 0.0 || b.hi <= 0.0;
}

// Cells are split at this fraction of their width, not at one half: a section running
// exactly along a dyadic parameter line (z = x y cut by z = 0 runs along u = 1/2) would
// otherwise lie on cell edges at every depth.
constexpr double kSplit = 0.4958578643762690;  // 1/2 - (sqrt(2) - 1) / 100

// Appends r on the boundary line from (u0, v0) to (u1, v1) after `a`, split until the
// quarter points lie within the tolerance of each chord.
void sampleLine(PatchSection& section, double u0, double v0, double u1, double v1,
                const SectionPoint& a, const SectionPoint& b, double tolerance, Piece& piece,
                int depth) {
  const SectionPoint m = section.at(0.5 * (u0 + u1), 0.5 * (v0 + v1));
  double deviation = distanceToSegment(m.point, a.point, b.point);
  for (double q : {0.25, 0.75})
    deviation = std::max(deviation, distanceToSegment(
        section.at(u0 + q * (u1 - u0), v0 + q * (v1 - v0)).point, a.point, b.point));
  if (depth < 40 && (deviation > tolerance || depth < 1)) {
    sampleLine(section, u0, v0, m.u, m.v, a, m, tolerance, piece, depth + 1);
    sampleLine(section, m.u, m.v, u1, v1, m, b, tolerance, piece, depth + 1);
    return;
  }
  piece.push_back(b);
}

void sectionPatch(PatchSection& section, double tolerance, std::vector<Piece>& pieces,
                  std::vector<SectionPoint>& touches, std::size_t& cells) {
  // Patch boundary edges lying in the plane (f vanishes identically along them) are part of
  // the section; the cells beside them see f >= 0 or <= 0 and are dropped.
  const double corners[4][4] = {{0, 0, 0, 1}, {1, 0, 1, 1}, {0, 0, 1, 0}, {0, 1, 1, 1}};
  for (const auto& c : corners) {
    const Bernstein1 edge = c[0] == c[2] ? isoU(section.f(), c[0]) : isoV(section.f(), c[1]);
    if (!isZero(edge)) continue;
    Piece piece{section.at(c[0], c[1])};
    sampleLine(section, c[0], c[1], c[2], c[3], piece.front(), section.at(c[2], c[3]), tolerance,
               piece, 0);
    pieces.push_back(std::move(piece));
  }
  std::vector<Cell> stack{{0.0, 1.0, 0.0, 1.0, 0}};
  while (!stack.empty()) {
    if (cells % 64 == 0) checkCancelled();
    const Cell cell = stack.back();
    stack.pop_back();
    ++cells;
    if (cannotCross(restrictTo(section.f(), cell.u0, cell.u1, cell.v0, cell.v1))) continue;
    const bool monotoneV = oneSigned(restrictTo(section.fv(), cell.u0, cell.u1, cell.v0, cell.v1));
    const bool monotoneU =
        !monotoneV && oneSigned(restrictTo(section.fu(), cell.u0, cell.u1, cell.v0, cell.v1));
    if (monotoneV || monotoneU) {
      GraphTracer(section, cell, /*swap=*/monotoneU, tolerance).trace(pieces);
      continue;
    }
    const double um = cell.u0 + kSplit * (cell.u1 - cell.u0);
    const double vm = cell.v0 + kSplit * (cell.v1 - cell.v0);
    if (cell.depth < kSectionMaxDepth) {
      const int d = cell.depth + 1;
      stack.push_back({cell.u0, um, cell.v0, vm, d});
      stack.push_back({um, cell.u1, cell.v0, vm, d});
      stack.push_back({cell.u0, um, vm, cell.v1, d});
      stack.push_back({um, cell.u1, vm, cell.v1, d});
      continue;
    }
    // A junction: grad f vanishes here to within the cell's resolution (the plane is
    // tangent to the surface). Every crossing on the cell's edges is joined to its centre.
    std::vector<SectionPoint> crossings;
    for (double v : section.rootsAlongU(cell.u0))
      if (v >= cell.v0 && v <= cell.v1) crossings.push_back(section.at(cell.u0, v));
    for (double v : section.rootsAlongU(cell.u1))
      if (v >= cell.v0 && v <= cell.v1) crossings.push_back(section.at(cell.u1, v));
    for (double u : section.rootsAlongV(cell.v0))
      if (u > cell.u0 && u < cell.u1) crossings.push_back(section.at(u, cell.v0));
    for (double u : section.rootsAlongV(cell.v1))
      if (u > cell.u0 && u < cell.u1) crossings.push_back(section.at(u, cell.v1));
    const SectionPoint centre = section.at(um, vm);
    if (crossings.empty()) {
      touches.push_back(centre);
      continue;
    }
    for (const SectionPoint& c : crossings) pieces.push_back({c, centre});
  }
}

// Union-find over indices.
class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  std::size_t find(std::size_t i) {
    while (parent_[i] != i) i = parent_[i] = parent_[parent_[i]];
    return i;
  }
  void unite(std::size_t a, std::size_t b) { parent_[find(a)] = find(b); }

 private:
  std::vector<std::size_t> parent_;
};

// Joins pieces whose ends meet into maximal curves: a graph whose nodes are the clustered
// ends and whose edges are the pieces; curves run between nodes of degree != 2, and what
// remains are cycles (closed loops).
// --- trimmed patches (surface.hpp's trims) ------------------------------------------------

// The point of the section nearest (u, v) along f's gradient in the parameter square: a few
// Newton steps on f(u, v) = n . r(u, v) - d from a point within the chordal tolerance of the
// curve (on a rational patch r = X / w; its zeros are the plane's).
SectionPoint onSection(const BezierPatch& patch, std::size_t index, Vec3 n, double d, double u, double v) {
  for (int iteration = 0; iteration < 8; ++iteration) {
    const Vec3 r = point(patch, u, v);
    const double f = dot(n, r) - d;
    const double fu = dot(n, derivativeU(patch, u, v)), fv = dot(n, derivativeV(patch, u, v));
    const double g2 = fu * fu + fv * fv;
    if (!(g2 > 0.0) || f == 0.0) break;
    u = std::clamp(u - f * fu / g2, 0.0, 1.0);
    v = std::clamp(v - f * fv / g2, 0.0, 1.0);
  }
  return {point(patch, u, v), index, u, v};
}

// The pieces of `piece` (on one trimmed patch) whose points lie in the patch's face: runs of
// kept vertices, each ended where the curve crosses a trimming curve. The crossing between a
// kept and a dropped vertex is found by bisection on the chord between them in (u, v), each
// point brought back onto the section (onSection) before it is classified: 48 halvings.
void clipPiece(const Piece& piece, const BezierPatch& patch, const PatchTrim& trim, Vec3 n, double d,
               std::vector<Piece>& out) {
  std::vector<bool> keep(piece.size());
  for (std::size_t i = 0; i < piece.size(); ++i) keep[i] = keepsPoint(trim, piece[i].u, piece[i].v);
  const auto crossing = [&](const SectionPoint& kept, const SectionPoint& dropped) {
    double in = 0.0, beyond = 1.0;  // along the chord from the kept vertex
    SectionPoint best = kept;
    for (int halving = 0; halving < 48; ++halving) {
      const double mid = 0.5 * (in + beyond);
      const SectionPoint p = onSection(patch, kept.patch, n, d, kept.u + mid * (dropped.u - kept.u),
                                       kept.v + mid * (dropped.v - kept.v));
      if (keepsPoint(trim, p.u, p.v)) {
        in = mid;
        best = p;
      } else {
        beyond = mid;
      }
    }
    return best;
  };
  Piece current;
  for (std::size_t i = 0; i < piece.size(); ++i) {
    if (keep[i]) {
      if (current.empty() && i > 0) current.push_back(crossing(piece[i], piece[i - 1]));
      current.push_back(piece[i]);
      continue;
    }
    if (!current.empty()) {
      current.push_back(crossing(piece[i - 1], piece[i]));
      out.push_back(std::move(current));
      current.clear();
    }
  }
  if (current.size() >= 2) out.push_back(std::move(current));
}

// Two ends are one node when they are within joinTolerance, or, on two patches of a CAD model,
// within kSeamJoinFactor times the larger of their patches' seam tolerances (surface.hpp) but
// no farther than the chordal tolerance: the joining chord then stands no farther from the
// true curve than the traced chords do.
void joinPieces(std::vector<Piece> pieces, double joinTolerance, double chordalTolerance, const Surface& surface,
                PlaneSection& out) {
  const std::size_t count = pieces.size();
  if (count == 0) return;
  // Cluster the 2 count ends (end 2i is piece i's first point, 2i + 1 its last).
  std::vector<std::size_t> order(2 * count);
  std::iota(order.begin(), order.end(), 0);
  auto endPoint = [&](std::size_t e) -> const Vec3& {
    const Piece& p = pieces[e / 2];
    return (e % 2 == 0 ? p.front() : p.back()).point;
  };
  auto endPatch = [&](std::size_t e) {
    const Piece& p = pieces[e / 2];
    return (e % 2 == 0 ? p.front() : p.back()).patch;
  };
  auto endSeam = [&](std::size_t e) {
    return std::min(chordalTolerance, kSeamJoinFactor * seamTolerance(surface, endPatch(e)));
  };
  double widest = 0.0;
  for (std::size_t e = 0; e < 2 * count; ++e) widest = std::max(widest, endSeam(e));
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return endPoint(a).x < endPoint(b).x; });
  DisjointSets ends(2 * count);
  for (std::size_t i = 0; i < order.size(); ++i) {
    if (i % 256 == 0) checkCancelled();
    for (std::size_t j = i + 1; j < order.size(); ++j) {
      if (endPoint(order[j]).x - endPoint(order[i]).x > std::max(joinTolerance, widest)) break;
      // A seam lies between two patches: ends on one patch meet exactly or not at all.
      const double reach = endPatch(order[i]) == endPatch(order[j])
                               ? joinTolerance
                               : std::max({joinTolerance, endSeam(order[i]), endSeam(order[j])});
      if (norm(endPoint(order[j]) - endPoint(order[i])) <= reach) ends.unite(order[i], order[j]);
    }
  }
  std::vector<std::size_t> node(2 * count);
  for (std::size_t e = 0; e < 2 * count; ++e) node[e] = ends.find(e);
  // Incidence: for each node, the ends attached to it.
  std::map<std::size_t, std::vector<std::size_t>> incident;
  for (std::size_t e = 0; e < 2 * count; ++e) incident[node[e]].push_back(e);

  // Components: nodes united through pieces.
  DisjointSets parts(2 * count);
  for (std::size_t i = 0; i < count; ++i) parts.unite(node[2 * i], node[2 * i + 1]);
  std::vector<std::size_t> roots;
  for (const auto& entry : incident) roots.push_back(parts.find(entry.first));
  std::sort(roots.begin(), roots.end());
  out.components += static_cast<std::size_t>(std::unique(roots.begin(), roots.end()) - roots.begin());

  std::vector<bool> used(count, false);
  // Walk from end e of an unused piece onward through degree-2 nodes.
  auto walk = [&](std::size_t firstEnd) {
    SectionCurve curve;
    std::size_t e = firstEnd;
    const std::size_t startNode = node[e];
    while (true) {
      const std::size_t i = e / 2;
      used[i] = true;
      Piece piece = pieces[i];
      if (e % 2 == 1) std::reverse(piece.begin(), piece.end());
      const std::size_t skip = curve.points.empty() ? 0 : 1;
      curve.points.insert(curve.points.end(), piece.begin() + static_cast<std::ptrdiff_t>(skip),
                          piece.end());
      const std::size_t otherEnd = e ^ 1U;
      const std::size_t at = node[otherEnd];
      const std::vector<std::size_t>& here = incident[at];
      if (at == startNode && here.size() == 2) {
        curve.closed = true;
        curve.points.back() = curve.points.front();
        break;
      }
      if (here.size() != 2) break;
      const std::size_t next = here[0] == otherEnd ? here[1] : here[0];
      if (used[next / 2]) break;
      e = next;
    }
    out.curves.push_back(std::move(curve));
  };
  for (const auto& [n, list] : incident) {
    if (list.size() == 2) continue;
    for (std::size_t e : list)
      if (!used[e / 2]) walk(e);
  }
  for (std::size_t i = 0; i < count; ++i)
    if (!used[i]) walk(2 * i);
}

}  // namespace

PlaneSection planeSection(const Surface& surface, const Vec3& normal, double offset,
                          double chordalTolerance) {
  const double length = norm(normal);
  if (!std::isfinite(length) || length == 0.0)
    throw Error(fmt::format("plane section: the plane normal ({}, {}, {}) must be finite and non-zero",
                            normal.x, normal.y, normal.z));
  if (!std::isfinite(offset))
    throw Error(fmt::format("plane section: the plane offset {} must be finite", offset));
  if (!(chordalTolerance > 0.0) || !std::isfinite(chordalTolerance))
    throw Error(fmt::format("plane section: the chordal tolerance {} must be positive",
                            chordalTolerance));
  const Vec3 n = normal / length;
  const double d = offset / length;
  PlaneSection out;
  std::vector<Piece> pieces;
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    checkCancelled();
    PatchSection section(surface.patches[i], i, n, d);
    const PatchTrim* trim = patchTrim(surface, i);
    if (trim == nullptr) {
      sectionPatch(section, chordalTolerance, pieces, out.touchPoints, out.cells);
      continue;
    }
    // A trimmed patch: its pieces clipped at the trimming curves, its touch points kept
    // only inside its face.
    if (classifyCell(*trim, ParameterCell{}) == CellPlace::outside) continue;
    std::vector<Piece> own;
    std::vector<SectionPoint> touches;
    sectionPatch(section, chordalTolerance, own, touches, out.cells);
    for (const Piece& piece : own) clipPiece(piece, surface.patches[i], *trim, n, d, pieces);
    for (const SectionPoint& touch : touches)
      if (keepsPoint(*trim, touch.u, touch.v)) out.touchPoints.push_back(touch);
  }
  const double scale = std::max(surfaceScale(surface), 1e-300);
  joinPieces(std::move(pieces), kJoinTolerance * scale, chordalTolerance, surface, out);
  return out;
}

double curveLength(const SectionCurve& curve) {
  double length = 0.0;
  for (std::size_t i = 1; i < curve.points.size(); ++i)
    length += norm(curve.points[i].point - curve.points[i - 1].point);
  return length;
}

}  // namespace scallop
