// The medial-axis search for the best circles (bestCircles, optimal_slicing.hpp): the
// candidates of eq (13) along each medial-axis edge, coarse to fine on large domains.

#include "scallop/slicing/optimal_slicing.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"
#include "scallop/slicing/medial_axis.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {
namespace {

Bernstein1 constant(double c) { return Bernstein1{{c}}; }

// R(t)^2 along a medial-axis edge as a polynomial in Bernstein form: eq (15) squared for a
// line/line bisector, eq (16) squared for a point/point one, eq (17) squared (|r(t) - f|^2,
// a quartic) for a point/line parabola.
Bernstein1 radiusSquared(const MedialEdge& edge, const Bernstein1& x, const Bernstein1& y) {
  switch (edge.bisector) {
    case MedialEdge::Bisector::lineLine: {
      const Bernstein1 r{{edge.d0 * edge.sinPsi, edge.d1 * edge.sinPsi}};
      return multiply(r, r);
    }
    case MedialEdge::Bisector::pointPoint: {
      const Bernstein1 d{{edge.d0, edge.d1}};
      return add(multiply(d, d), constant(edge.halfGap * edge.halfGap));
    }
    case MedialEdge::Bisector::pointLine: {
      const Vec2 focus = edge.siteA.a;
      const Bernstein1 dx = subtract(x, constant(focus.x));
      const Bernstein1 dy = subtract(y, constant(focus.y));
      return add(multiply(dx, dx), multiply(dy, dy));
    }
  }
  return constant(0.0);
}

// The parameters in (0, 1) where d/dt tan(alpha) = 0 along the edge: eq (13),
//   (x^2 + y^2 + R^2 + 1) R' - 2 (x x' + y y') R = 0,
// multiplied by 2R and written with Q = R^2 (so R R' = Q'/2):
//   (x^2 + y^2 + Q + 1) Q' - 4 (x x' + y y') Q = 0,
// a polynomial (degree 4 on linear edges with quadratic Q, 7 on parabolic ones with quartic
// Q, as the paper counts after rationalising). Its extra roots (R = 0) are harmless: every
// candidate is evaluated.
std::vector<double> stationaryParameters(const MedialEdge& edge) {
  Bernstein1 x;
  Bernstein1 y;
  if (edge.kind == MedialEdge::Kind::linear) {
    x = Bernstein1{{edge.control[0].x, edge.control[1].x}};
    y = Bernstein1{{edge.control[0].y, edge.control[1].y}};
  } else {
    x = Bernstein1{{edge.control[0].x, edge.control[1].x, edge.control[2].x}};
    y = Bernstein1{{edge.control[0].y, edge.control[1].y, edge.control[2].y}};
  }
  const Bernstein1 q = radiusSquared(edge, x, y);
  const Bernstein1 rho2 = add(multiply(x, x), multiply(y, y));
  const Bernstein1 left = multiply(add(add(rho2, q), constant(1.0)), derivative(q));
  const Bernstein1 xdx = add(multiply(x, derivative(x)), multiply(y, derivative(y)));
  const Bernstein1 f = subtract(left, scale(multiply(xdx, q), 4.0));
  if (isZero(f)) return {};
  return realRoots(f);
}

// ---------------------------------------------------------------------------------------
// The medial-axis search (bestCircles), coarse to fine.

// The coarse domain's target size, in segments: this times the square root of the fine
// count. The search costs about two medial axes of the mixed domain, whose segments are the
// coarse ones plus the fine chains of the few dozen coarse segments near the best circles
// (each standing for fine / coarse fine segments): the sum is least near sqrt(dozens x fine).
// On the paper's surfaces at ~100,000 segments: ~3,000 coarse ones, ~6,000-9,000 searched.
constexpr double kCoarseSegmentsPerRootFine = 10.0;
// Refinement rounds before the search gives up and takes the full-resolution domain.
constexpr int kMaxRefinementRounds = 10;
// Simplifications tried (delta halved each time) when the simplified loops cross (where the
// domain is thinner than delta) before the full-resolution domain is taken.
constexpr int kSimplificationAttempts = 3;

// Every candidate circle of a medial axis, in edge order: each edge's ends and the roots of
// eq (13) on it, where alpha along the edge has its extrema, so that edgeBestAlpha also
// bounds alpha over the whole edge.
struct AxisCandidates {
  std::vector<RatedCircle> circles;
  std::vector<double> edgeBestAlpha;  // per edge; -1: no usable circle on it
  std::size_t best = 0;               // index into circles of the first greatest alpha
  std::size_t boundedEdges = 0;       // edges rated at their ends alone (see rateCandidates)
};

// An upper bound of alpha over the edge's circles (pi when they may reach the origin).
// By eq (12), tan alpha = 2R / (rho^2 - R^2 + 1) with rho = |c|: while rho > R it grows with
// R and falls with rho. The centre stays in the hull of the edge's control points (a
// segment, or the parabola's control triangle), which bounds rho from below. R is convex in
// the centre's position (the distance to a point; to a line, affine, on a line/line
// bisector), so its largest value on that hull is at a control point: the ends' radii, and
// on a parabola the control points' distances to the focus (eq 17). A relative 1e-9 covers
// the rounding of either side.
double alphaBound(const MedialEdge& edge) {
  const Vec2 origin{0.0, 0.0};
  double rMax = std::max(radiusAt(edge, 0.0), radiusAt(edge, 1.0));
  double rhoMin = 0.0;
  if (edge.kind == MedialEdge::Kind::linear) {
    rhoMin = distanceToSegment(origin, edge.control[0], edge.control[1]);
  } else {
    const std::array<Vec2, 3>& p = edge.control;
    for (const Vec2& q : p) rMax = std::max(rMax, norm(q - edge.siteA.a));
    const double s0 = cross(p[1] - p[0], origin - p[0]);
    const double s1 = cross(p[2] - p[1], origin - p[1]);
    const double s2 = cross(p[0] - p[2], origin - p[2]);
    const bool inside = (s0 >= 0.0 && s1 >= 0.0 && s2 >= 0.0) || (s0 <= 0.0 && s1 <= 0.0 && s2 <= 0.0);
    if (!inside) {
      rhoMin = std::min({distanceToSegment(origin, p[0], p[1]), distanceToSegment(origin, p[1], p[2]),
                         distanceToSegment(origin, p[2], p[0])});
    }
  }
  const double d = rhoMin * rhoMin - rMax * rMax + 1.0;
  if (!(d > 0.0) || !std::isfinite(rMax)) return std::numbers::pi;
  return std::atan2(2.0 * rMax, d) * (1.0 + 1e-9) + 1e-15;
}

// The candidates of `axis` (see AxisCandidates). The interior roots of eq (13) matter only
// on edges that can hold a circle within `windowRad` of the best: every edge's ends are rated
// first, and an edge whose alphaBound is below the best of them less the window keeps its
// ends alone, with the bound as its edgeBestAlpha (still an upper bound, which is all the
// coarse-to-fine test asks of it). The best circle and the rivals come out as if every root
// had been rated, in the same order: a bypassed root's alpha is below every rival's.
AxisCandidates rateCandidates(const MedialAxis& axis, double windowRad) {
  double bestEnd = -1.0;
  for (const MedialEdge& edge : axis.edges) {
    for (double t : {0.0, 1.0}) {
      const double r = radiusAt(edge, t);
      const double rho = norm(pointAt(edge, t));
      if (r > 0.0 && rho > r) bestEnd = std::max(bestEnd, alphaOfPlaneCircleRad(rho, r));
    }
  }
  AxisCandidates out;
  out.edgeBestAlpha.assign(axis.edges.size(), -1.0);
  for (std::size_t e = 0; e < axis.edges.size(); ++e) {
    if (e % 256 == 0) checkCancelled();
    const MedialEdge& edge = axis.edges[e];
    std::vector<double> ts;
    const double bound = bestEnd >= 0.0 ? alphaBound(edge) : std::numbers::pi;
    const bool bypassed = bound < bestEnd - windowRad;
    if (!bypassed) ts = stationaryParameters(edge);
    ts.push_back(0.0);
    ts.push_back(1.0);
    for (double t : ts) {
      const Vec2 c = pointAt(edge, t);
      const double r = radiusAt(edge, t);
      const double rho = norm(c);
      // Circles that hold the origin (the south pole, a surface normal's antipode) are not
      // in the complement; the medial axis never yields them but rounding might.
      if (!(r > 0.0) || rho <= r) {
        // Rated as the best possible for the coarse-to-fine test, which then examines it.
        if (r > 0.0) out.edgeBestAlpha[e] = std::numbers::pi;
        continue;
      }
      const double alpha = alphaOfPlaneCircleRad(rho, r);  // eq (12)
      if (out.circles.empty() || alpha > out.circles[out.best].alphaRad) out.best = out.circles.size();
      out.circles.push_back({alpha, {c, r}});
      out.edgeBestAlpha[e] = std::max(out.edgeBestAlpha[e], alpha);
    }
    if (bypassed) {
      out.edgeBestAlpha[e] = std::max(out.edgeBestAlpha[e], bound);
      ++out.boundedEdges;
    }
  }
  return out;
}

BestCircles searchResult(MedialAxis axis, const AxisCandidates& candidates, double windowRad) {
  if (candidates.circles.empty()) throw Error("the medial axis of the Gauss map's complement has no usable circle");
  BestCircles out;
  out.best = candidates.circles[candidates.best];
  for (const RatedCircle& c : candidates.circles) {
    if (c.alphaRad >= out.best.alphaRad - windowRad) out.rivals.push_back(c);
  }
  std::stable_sort(out.rivals.begin(), out.rivals.end(),
                   [](const RatedCircle& a, const RatedCircle& b) { return a.alphaRad > b.alphaRad; });
  out.axis = std::move(axis);
  out.boundedEdges = candidates.boundedEdges;
  return out;
}

std::size_t segmentCount(const PlanarDomain& domain) {
  std::size_t n = 0;
  for (const auto& loop : domain.loops) n += loop.size();
  return n;
}

// Douglas-Peucker on a closed loop: the indices (increasing, starting with 0) of the
// vertices kept so that every vertex between two consecutive kept ones lies within `delta`
// of the segment joining them. Vertex 0 and the loop's extreme vertices in x and y are
// always kept, so that the simplified domain has the same bounding box, hence the same
// integer grid in medialAxis (medial_axis.hpp), as the full one: the vertices they share are
// quantised alike and the circles they define come out bit for bit. Iterative (explicit
// stack); O(n log n) on smooth loops, where the farthest vertex splits a chain near its
// middle.
std::vector<std::uint32_t> douglasPeucker(const std::vector<Vec2>& loop, double delta) {
  const std::size_t n = loop.size();
  if (n < 3) {
    std::vector<std::uint32_t> all(n);
    std::iota(all.begin(), all.end(), 0U);
    return all;
  }
  std::vector<char> keep(n, 0);
  std::array<std::size_t, 5> anchors{0, 0, 0, 0, 0};
  for (std::size_t i = 1; i < n; ++i) {
    if (loop[i].x < loop[anchors[1]].x) anchors[1] = i;
    if (loop[i].x > loop[anchors[2]].x) anchors[2] = i;
    if (loop[i].y < loop[anchors[3]].y) anchors[3] = i;
    if (loop[i].y > loop[anchors[4]].y) anchors[4] = i;
  }
  for (std::size_t a : anchors) keep[a] = 1;
  std::vector<std::size_t> sorted(anchors.begin(), anchors.end());
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  // Chains [first, last] in unrolled indices (last may be n, i.e. vertex 0 again).
  std::vector<std::pair<std::size_t, std::size_t>> stack;
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    stack.push_back({sorted[k], k + 1 < sorted.size() ? sorted[k + 1] : n});
  }
  while (!stack.empty()) {
    const auto [first, last] = stack.back();
    stack.pop_back();
    if (last - first < 2) continue;
    const Vec2 a = loop[first];
    const Vec2 b = loop[last % n];
    double farthest = -1.0;
    std::size_t split = first;
    for (std::size_t i = first + 1; i < last; ++i) {
      const double d = distanceToSegment(loop[i], a, b);
      if (d > farthest) farthest = d, split = i;
    }
    if (farthest <= delta) continue;
    keep[split] = 1;
    stack.push_back({first, split});
    stack.push_back({split, last});
  }
  std::vector<std::uint32_t> kept;
  for (std::size_t i = 0; i < n; ++i) {
    if (keep[i]) kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

// The Douglas-Peucker tolerance delta that leaves about kCoarseSegmentsPerRootFine x
// sqrt(fine) coarse segments: one trial at 1e-6 of the bounding box's diagonal, then the
// count's law on smooth curves (a chord of sagitta delta spans a length proportional to
// sqrt(delta), so the count goes as delta^-1/2), within a factor 100 of the trial.
double simplificationTolerance(const PlanarDomain& domain) {
  Vec2 low{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  Vec2 high = -low;
  std::size_t fine = 0;
  for (const auto& loop : domain.loops) {
    fine += loop.size();
    for (const Vec2& p : loop) {
      low = {std::min(low.x, p.x), std::min(low.y, p.y)};
      high = {std::max(high.x, p.x), std::max(high.y, p.y)};
    }
  }
  const double trial = 1e-6 * norm(high - low);
  if (!std::isfinite(trial) || !(trial > 0.0)) return 0.0;
  std::size_t coarse = 0;
  for (const auto& loop : domain.loops) {
    if (loop.size() >= 3) coarse += douglasPeucker(loop, trial).size();
  }
  const double target = kCoarseSegmentsPerRootFine * std::sqrt(static_cast<double>(fine));
  const double ratio = static_cast<double>(std::max<std::size_t>(coarse, 1)) / target;
  return trial * std::clamp(ratio * ratio, 1e-2, 1e2);
}

// A uniform grid over segments for the verification's query: the segments that may lie
// within distance `outer` of a point, skipping the cells wholly within distance `inner`
// (inside an empty maximal disc, where no boundary lies). Cells are registered by each
// segment's bounding box. A query costs O(rows + cells along the annulus).
class SegmentGrid {
 public:
  SegmentGrid(const std::vector<std::array<Vec2, 2>>& segments, Vec2 low, Vec2 high) {
    origin_ = low;
    const double extent = std::max({high.x - low.x, high.y - low.y, 1e-300});
    // About two cells per segment: the segments lie along curves, so most cells stay
    // empty and an occupied one holds a few.
    const double side = std::clamp(std::ceil(std::sqrt(2.0 * static_cast<double>(segments.size()))), 1.0, 2048.0);
    cell_ = extent / side;
    columns_ = static_cast<int>(std::ceil((high.x - low.x) / cell_)) + 1;
    rows_ = static_cast<int>(std::ceil((high.y - low.y) / cell_)) + 1;
    start_.assign(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_) + 1, 0);
    auto forCells = [this](const std::array<Vec2, 2>& s, auto&& f) {
      const int i0 = column(std::min(s[0].x, s[1].x)), i1 = column(std::max(s[0].x, s[1].x));
      const int j0 = row(std::min(s[0].y, s[1].y)), j1 = row(std::max(s[0].y, s[1].y));
      for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) f(index(i, j));
    };
    for (const auto& s : segments) forCells(s, [this](std::size_t c) { ++start_[c + 1]; });
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    items_.resize(start_.back());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t k = 0; k < segments.size(); ++k) {
      forCells(segments[k], [&](std::size_t c) { items_[fill[c]++] = static_cast<std::uint32_t>(k); });
    }
  }

  template <typename Visit>
  void forEachNear(Vec2 p, double inner, double outer, Visit&& visit) const {
    const int j0 = row(p.y - outer), j1 = row(p.y + outer);
    for (int j = j0; j <= j1; ++j) {
      const double ya = origin_.y + j * cell_, yb = ya + cell_;
      const double dyMin = std::max({ya - p.y, 0.0, p.y - yb});
      if (dyMin > outer) continue;
      const double dyMax = std::max(std::abs(p.y - ya), std::abs(p.y - yb));
      const double half = std::sqrt(outer * outer - dyMin * dyMin);
      const int i0 = column(p.x - half), i1 = column(p.x + half);
      // Columns [skip0, skip1] lie wholly within `inner` of p on this row.
      int skip0 = i1 + 1, skip1 = i1;
      if (inner > dyMax) {
        const double w = std::sqrt(inner * inner - dyMax * dyMax);
        skip0 = static_cast<int>(std::clamp(std::floor((p.x - w - origin_.x) / cell_) + 1.0, -1.0, double(columns_)));
        skip1 = static_cast<int>(std::clamp(std::ceil((p.x + w - origin_.x) / cell_) - 2.0, -2.0, double(columns_)));
      }
      for (int i = i0; i <= i1; ++i) {
        if (i >= skip0 && i <= skip1) {
          i = skip1;
          continue;
        }
        const std::size_t c = index(i, j);
        for (std::uint32_t k = start_[c]; k < start_[c + 1]; ++k) visit(items_[k]);
      }
    }
  }

 private:
  int column(double x) const {
    return static_cast<int>(std::clamp(std::floor((x - origin_.x) / cell_), 0.0, double(columns_ - 1)));
  }
  int row(double y) const {
    return static_cast<int>(std::clamp(std::floor((y - origin_.y) / cell_), 0.0, double(rows_ - 1)));
  }
  std::size_t index(int i, int j) const {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(i);
  }

  Vec2 origin_;
  double cell_ = 1.0;
  int columns_ = 1;
  int rows_ = 1;
  std::vector<std::uint32_t> start_;  // CSR: cell c holds items_[start_[c], start_[c + 1])
  std::vector<std::uint32_t> items_;
};

// The domain of the coarse-to-fine search: every loop simplified by Douglas-Peucker at
// `delta`, each coarse segment standing for the fine chain between its two kept vertices,
// and the "mixed" domain M in which the refined coarse segments are replaced by their
// chains.
//
// Why M's optimum is the full domain F's (the test in violations()). Every fine vertex of a
// chain lies within delta of its coarse segment, hence so does the whole chain, and every
// point of the segment lies within delta of the chain (the chain's projection onto the
// segment covers it), so M and F differ only inside the delta-neighbourhoods of the
// unrefined coarse segments. The stereographic projection's conformal factor is
// 2 / (1 + |p|^2) <= 2: moving a circle's boundary by delta in the plane changes its cap's
// angular radius alpha by at most 2 delta (and alpha <= 2R). Let C* be an optimal (or
// rival) circle of F, with alpha* > 4 delta, so its centre is not within delta of an
// unrefined coarse segment and lies in M. C* shrunk by delta avoids M's boundary, so lies in
// M, hence in a maximal disc D of M, centred on M's medial axis, with
// alpha(D) >= alpha(C*) - 2 delta. The test: every point of M's axis whose circle has
// alpha >= alpha_M - window - 3 delta (2 delta, and delta for rounding) is farther than
// R + 2 delta from every unrefined coarse segment. Along each edge, alpha is monotone between
// the roots of eq (13), so the parts above that threshold are intervals (found by
// bisection); on them g(t) = dist(c(t), unrefined) - R(t), 2-Lipschitz in arc length, is
// sampled from one end to the other, each sample covering the arc length
// (g - 2 delta - rounding) / 2 ahead of it; a sample that covers less than h / 2 (h = delta)
// fails, and the coarse segments within R + 2 delta + h of it are refined. If no sample
// fails, C* (within delta of D) stays more than delta from every unrefined segment, so it
// touches only refined parts (common to M and F) and is a maximal disc of M:
// alpha_M >= alpha*. Conversely M's best circle and rivals pass the test, so they are empty
// maximal discs of F touching the same sites (and alpha* >= alpha_M > 5 delta, as assumed).
// Hence alpha_M = alpha*, and the circles within the window of it are the same in M and F,
// up to the rounding of the roots of eq (13) on edges of different extent: bit for bit in
// practice, as M's refined vertices are F's, on the same integer grid (see douglasPeucker),
// unless Boost's diagram of one of them fails validation and is rebuilt rotated (then the
// two agree to the medial axis's tolerance).
class CoarseToFineDomain {
 public:
  CoarseToFineDomain(const PlanarDomain& fine, double delta) : fine_(fine), delta_(delta) {
    for (std::size_t l = 0; l < fine.loops.size(); ++l) {
      const std::vector<Vec2>& loop = fine.loops[l];
      if (loop.empty()) continue;
      std::vector<std::uint32_t> kept = douglasPeucker(loop, delta);
      // A loop that simplifies below a triangle is thinner than 2 delta: kept whole (and a
      // degenerate one left for medialAxis to explain).
      const bool whole = kept.size() < 3;
      for (std::size_t k = 0; k < kept.size(); ++k) {
        const std::uint32_t last = k + 1 < kept.size() ? kept[k + 1] : static_cast<std::uint32_t>(loop.size());
        segments_.push_back({static_cast<std::uint32_t>(l), kept[k], last, whole});
      }
    }
  }

  double delta() const { return delta_; }

  // M: each loop's coarse segments, the refined ones replaced by their fine chains.
  PlanarDomain mixed() const {
    PlanarDomain out;
    out.loops.resize(fine_.loops.size());
    for (const Segment& s : segments_) {
      const std::vector<Vec2>& loop = fine_.loops[s.loop];
      std::vector<Vec2>& into = out.loops[s.loop];
      into.push_back(loop[s.first]);
      if (s.refined) into.insert(into.end(), loop.begin() + s.first + 1, loop.begin() + s.last);
    }
    return out;
  }

  // The unrefined coarse segments that fail the test above for M's axis and its candidates.
  std::vector<std::size_t> violations(const MedialAxis& axis, const AxisCandidates& candidates,
                                      double windowRad) const {
    std::vector<std::size_t> ids;
    std::vector<std::array<Vec2, 2>> coarse;
    Vec2 low{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    Vec2 high = -low;
    for (std::size_t k = 0; k < segments_.size(); ++k) {
      const Segment& s = segments_[k];
      if (s.refined) continue;
      const std::vector<Vec2>& loop = fine_.loops[s.loop];
      const std::array<Vec2, 2> ab{loop[s.first], loop[s.last % loop.size()]};
      for (const Vec2& p : ab) {
        low = {std::min(low.x, p.x), std::min(low.y, p.y)};
        high = {std::max(high.x, p.x), std::max(high.y, p.y)};
      }
      ids.push_back(k);
      coarse.push_back(ab);
    }
    if (coarse.empty()) return {};
    const SegmentGrid grid(coarse, low, high);
    const double h = delta_;
    // The axis is exact for the integer-rounded domain; its radii to within its tolerance.
    const double clearance = 2.0 * delta_ + 4.0 * axis.tolerance;
    const double threshold = candidates.circles[candidates.best].alphaRad - windowRad - 3.0 * delta_;
    std::vector<char> violated(coarse.size(), 0);
    // The test at one point of the axis: the arc length ahead of it in which g = dist - R
    // stays above `clearance` (g is 2-Lipschitz), or, when that is below h/2, a failure: the
    // segments closer than R + clearance + h are marked (which lets the march go on h/2).
    auto clearAhead = [&](Vec2 c, double r) {
      const double reach = std::max(h, std::min(0.25 * r, 64.0 * h));  // the longest stride sought
      double nearest = r + clearance + 2.0 * reach;
      grid.forEachNear(c, r - delta_, nearest, [&](std::uint32_t k) {
        if (!violated[k]) nearest = std::min(nearest, distanceToSegment(c, coarse[k][0], coarse[k][1]));
      });
      const double ahead = 0.5 * (nearest - r - clearance);
      if (ahead >= 0.5 * h) return ahead;
      const double limit = r + clearance + h;
      grid.forEachNear(c, r - delta_, limit, [&](std::uint32_t k) {
        if (distanceToSegment(c, coarse[k][0], coarse[k][1]) <= limit) violated[k] = 1;
      });
      return 0.5 * h;
    };
    auto alphaAt = [](const MedialEdge& edge, double t) {
      return alphaOfPlaneCircleRad(norm(pointAt(edge, t)), radiusAt(edge, t));
    };
    for (std::size_t e = 0; e < axis.edges.size(); ++e) {
      if (candidates.edgeBestAlpha[e] < threshold) continue;
      const MedialEdge& edge = axis.edges[e];
      // |c'(t)| bounds the arc length per unit t: the control polygon's longest leg, doubled
      // on a quadratic.
      const auto& p = edge.control;
      const double speed = edge.kind == MedialEdge::Kind::linear
                               ? norm(p[1] - p[0])
                               : 2.0 * std::max(norm(p[1] - p[0]), norm(p[2] - p[1]));
      // alpha is monotone between consecutive roots of eq (13) (its derivative has the sign
      // of that polynomial over R > 0), so {alpha >= threshold} is a union of intervals whose
      // ends bisection finds; each is marched with the test above.
      std::vector<double> ts = stationaryParameters(edge);
      ts.push_back(0.0);
      ts.push_back(1.0);
      for (double& t : ts) t = std::clamp(t, 0.0, 1.0);
      std::sort(ts.begin(), ts.end());
      for (std::size_t k = 0; k + 1 < ts.size(); ++k) {
        double lo = ts[k], hi = ts[k + 1];
        const double alphaLo = alphaAt(edge, lo), alphaHi = alphaAt(edge, hi);
        if (std::max(alphaLo, alphaHi) < threshold) continue;
        if (std::min(alphaLo, alphaHi) < threshold) {
          // Keep the bracket's end below the threshold: the interval only grows.
          const bool rising = alphaLo < alphaHi;
          double below = rising ? lo : hi, above = rising ? hi : lo;
          for (int i = 0; i < 60 && std::abs(above - below) * speed > 0.25 * h; ++i) {
            const double mid = 0.5 * (below + above);
            (alphaAt(edge, mid) < threshold ? below : above) = mid;
          }
          (rising ? lo : hi) = below;
        }
        for (double t = lo;;) {
          const double ahead = clearAhead(pointAt(edge, t), radiusAt(edge, t));
          if (t >= hi || !(speed > 0.0)) break;
          t = std::min(hi, t + ahead / speed);
        }
      }
    }
    std::vector<std::size_t> out;
    for (std::size_t k = 0; k < coarse.size(); ++k) {
      if (violated[k]) out.push_back(ids[k]);
    }
    return out;
  }

  // Replaces the given coarse segments, and their neighbours in their loops, by their fine
  // chains. The neighbours: the circles move a little when their contacts are refined, and
  // would otherwise often call for one more round (one medial axis of the whole mixed
  // domain) for a segment or two.
  void refine(const std::vector<std::size_t>& ids) {
    for (std::size_t k : ids) {
      segments_[k].refined = true;
      const Segment& s = segments_[k];
      if (k > 0 && segments_[k - 1].loop == s.loop) segments_[k - 1].refined = true;
      if (k + 1 < segments_.size() && segments_[k + 1].loop == s.loop) segments_[k + 1].refined = true;
    }
  }

 private:
  struct Segment {
    std::uint32_t loop = 0;
    std::uint32_t first = 0;  // kept vertex where the segment starts
    std::uint32_t last = 0;   // the next kept vertex (the loop's size for vertex 0)
    bool refined = false;     // replaced by the fine chain first..last in M
  };

  const PlanarDomain& fine_;
  double delta_;
  std::vector<Segment> segments_;
};

}  // namespace

BestCircles bestCircles(const PlanarDomain& domain, const BestCirclesOptions& options) {
  if (!(options.windowRad >= 0.0) || !std::isfinite(options.windowRad)) {
    throw Error(fmt::format("bestCircles: the window must be a finite angle >= 0, got {} rad", options.windowRad));
  }
  const std::size_t fineSegments = segmentCount(domain);
  auto searchWhole = [&](int refinements) {
    MedialAxis axis = medialAxis(domain);
    const AxisCandidates candidates = rateCandidates(axis, options.windowRad);
    BestCircles out = searchResult(std::move(axis), candidates, options.windowRad);
    out.segments = fineSegments;
    out.refinements = refinements;
    return out;
  };
  if (!options.coarseToFine || fineSegments <= options.coarseToFineMinSegments) return searchWhole(0);
  const double delta = simplificationTolerance(domain);
  if (!(delta > 0.0)) return searchWhole(0);  // degenerate input: medialAxis explains
  int refinements = 0;
  for (int attempt = 0; attempt < kSimplificationAttempts; ++attempt) {
    CoarseToFineDomain coarse(domain, std::ldexp(delta, -attempt));
    for (int round = 0;; ++round) {
      const PlanarDomain mixed = coarse.mixed();
      MedialAxis axis;
      try {
        axis = medialAxis(mixed);
      } catch (const Cancelled&) {
        throw;
      } catch (const Error&) {
        break;  // the simplified loops cross where the domain is thinner than delta
      }
      const AxisCandidates candidates = rateCandidates(axis, options.windowRad);
      // The proof needs alpha* > 4 delta (see CoarseToFineDomain); below that delta is as
      // large as the circles, and the full domain is cheaper than refining everything.
      if (candidates.circles.empty() || !(candidates.circles[candidates.best].alphaRad > 5.0 * coarse.delta())) {
        return searchWhole(refinements);
      }
      const std::vector<std::size_t> violations = coarse.violations(axis, candidates, options.windowRad);
      if (violations.empty()) {
        BestCircles out = searchResult(std::move(axis), candidates, options.windowRad);
        out.segments = segmentCount(mixed);
        out.refinements = refinements;
        out.simplificationTolerance = coarse.delta();
        return out;
      }
      if (round + 1 >= kMaxRefinementRounds) return searchWhole(refinements);
      coarse.refine(violations);
      ++refinements;
    }
  }
  return searchWhole(refinements);
}

}  // namespace scallop
