// The symmetrized Gauss map: a quadtree of regular, traced and small fold cells over each
// patch, their images (edges and traced parabolic arcs) merged into sheets, and the union.
// See include/scallop/gauss_map.hpp for the contract.

#include "scallop/slicing/gauss_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <clipper.hpp>
#include <fmt/format.h>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/job_control.hpp"

namespace scallop {
namespace {

struct UV {
  double u = 0.0;
  double v = 0.0;
};

double angleBetween(const Vec3& a, const Vec3& b) {
  // atan2(|a x b|, a . b): accurate for small and large angles alike.
  return std::atan2(norm(cross(a, b)), dot(a, b));
}

// Everything a patch needs for the Gauss map, computed once.
struct PatchData {
  const BezierPatch* patch = nullptr;
  std::size_t index = 0;  // in the surface, for error messages
  // r_u x r_v in exact Bernstein form, collapsed edges factored out (its limits there; see
  // normalDirectionPolynomials).
  std::array<Bernstein2, 3> normal;
  // The Gaussian curvature numerator (sign of K), its edge factors split off (see
  // curvatureSignPolynomial): a parabolic line along a patch edge is none here.
  Bernstein2 curvature;
  EdgePowers curvaturePowers;
  bool developable = false;          // K = 0 identically (to rounding)
  // Patch edges v = 0, u = 1, v = 1, u = 0 that another patch may share or touch (a seam):
  // there two patches' polygons of one curve must both be within the tolerance, or the
  // sliver between them would open a gap in Omega (see BoundaryBand).
  std::array<bool, 4> seam{false, false, false, false};
};

PatchData makePatchData(const BezierPatch& patch) {
  PatchData data;
  data.patch = &patch;
  data.normal = normalDirectionPolynomials(patch).polynomials;
  CurvatureSign sign = curvatureSignPolynomial(patch);
  data.curvature = std::move(sign.polynomial);
  data.curvaturePowers = sign.powers;
  // K's numerator is (r_uu . N)(r_vv . N) - (r_uv . N)^2, of the order of |N|^2 |r''|^2: call
  // it identically zero when every coefficient is below 1e-12 of that scale. |r''| is taken
  // at least 1e-6 |r'|: a plane whose control points carry rounding has second derivatives
  // of rounding size, and so a K of the order of its own scale, yet it is flat (a curved
  // patch that flat has a Gauss image far below any tolerance, which its boundary's
  // normals, the image of a developable patch, then cover).
  const Bounds nb = bounds(normalLengthSquared(patch));
  const double nScale = std::sqrt(std::max(std::abs(nb.lo), std::abs(nb.hi)));
  double first = 0.0;
  double second = 0.0;
  for (double u : {0.0, 0.5, 1.0}) {
    for (double v : {0.0, 0.5, 1.0}) {
      first = std::max({first, norm(derivativeU(patch, u, v)), norm(derivativeV(patch, u, v))});
      for (const auto& [du, dv] : {std::pair{2, 0}, std::pair{1, 1}, std::pair{0, 2}}) {
        second = std::max(second, norm(secondDerivative(patch, u, v, du, dv)));
      }
    }
  }
  second = std::max(second, 1e-6 * first);
  double largest = 0.0;
  for (double c : data.curvature.coefficients) largest = std::max(largest, std::abs(c));
  data.developable = largest <= 1e-12 * std::max(1e-300, nScale * nScale * second * second);
  return data;
}

// PatchData::seam: an edge whose control points' box, grown by 1e-9 of the surface's size,
// meets another patch's box (conservative: edges that merely come near count too).
void markSeams(std::vector<PatchData>& patches) {
  if (patches.size() < 2) return;
  struct Box {
    Vec3 lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
            std::numeric_limits<double>::infinity()};
    Vec3 hi = -lo;
    void add(const Vec3& p) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    bool meets(const Box& o, double slack) const {
      return lo.x <= o.hi.x + slack && o.lo.x <= hi.x + slack && lo.y <= o.hi.y + slack &&
             o.lo.y <= hi.y + slack && lo.z <= o.hi.z + slack && o.lo.z <= hi.z + slack;
    }
  };
  std::vector<Box> boxes(patches.size());
  Box all;
  for (std::size_t i = 0; i < patches.size(); ++i) {
    for (const Vec3& p : patches[i].patch->control) boxes[i].add(p), all.add(p);
  }
  const double slack = 1e-9 * norm(all.hi - all.lo);
  for (std::size_t i = 0; i < patches.size(); ++i) {
    const BezierPatch& p = *patches[i].patch;
    const int m = p.degreeU, n = p.degreeV;
    std::array<Box, 4> edges;  // v = 0, u = 1, v = 1, u = 0
    for (int j = 0; j <= m; ++j) edges[0].add(p.at(j, 0)), edges[2].add(p.at(j, n));
    for (int k = 0; k <= n; ++k) edges[3].add(p.at(0, k)), edges[1].add(p.at(m, k));
    for (std::size_t e = 0; e < 4; ++e) {
      for (std::size_t other = 0; other < patches.size(); ++other) {
        if (other != i && edges[e].meets(boxes[other], slack)) patches[i].seam[e] = true;
      }
    }
  }
}

Bernstein2 combine(const std::array<Bernstein2, 3>& n, const Vec3& w) {
  Bernstein2 out = n[0];
  for (std::size_t i = 0; i < out.coefficients.size(); ++i) {
    out.coefficients[i] = w.x * n[0].coefficients[i] + w.y * n[1].coefficients[i] +
                          w.z * n[2].coefficients[i];
  }
  return out;
}

bool strictSign(const Bernstein2& p) {
  const Bounds b = bounds(p);
  return b.lo > 0.0 || b.hi < 0.0;
}

// ---------------------------------------------------------------------------------------
// Membership: is m a unit normal of the patch? r_u x r_v = N must be parallel to m with
// N . m > 0: with e1, e2 spanning the plane orthogonal to m, f1 = N . e1 and f2 = N . e2
// vanish together while g = N . m > 0. Cells where f1 or f2 keeps a strict sign, or g <= 0,
// are excluded (the Bernstein coefficients bound the polynomial); the surviving small cells
// are confirmed by Newton's method on (f1, f2).
// ---------------------------------------------------------------------------------------

struct MembershipCell {
  Bernstein2 f1, f2, g;
  double u0, u1, v0, v1;
  int depth;
};

// Whether r_u x r_v (given in Bernstein form over some parameter box, mapped to [0, 1]^2)
// is a positive multiple of m somewhere on the box.
bool hasNormal(const std::array<Bernstein2, 3>& normal, const Vec3& m) {
  const Vec3 helper = std::abs(m.x) < 0.6 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  const Vec3 e1 = normalized(cross(m, helper));
  const Vec3 e2 = cross(m, e1);
  const Bernstein2 f1 = combine(normal, e1);
  const Bernstein2 f2 = combine(normal, e2);
  const Bernstein2 g = combine(normal, m);
  const Bernstein2 f1u = derivativeU(f1), f1v = derivativeV(f1);
  const Bernstein2 f2u = derivativeU(f2), f2v = derivativeV(f2);

  auto newton = [&](double u, double v, double lo0, double hi0, double lo1, double hi1) {
    for (int i = 0; i < 30; ++i) {
      const double a = evaluate(f1, u, v), b = evaluate(f2, u, v);
      const double j11 = evaluate(f1u, u, v), j12 = evaluate(f1v, u, v);
      const double j21 = evaluate(f2u, u, v), j22 = evaluate(f2v, u, v);
      const double det = j11 * j22 - j12 * j21;
      if (det == 0.0 || !std::isfinite(det)) return false;
      const double du = (a * j22 - b * j12) / det;
      const double dv = (j11 * b - j21 * a) / det;
      u -= du;
      v -= dv;
      if (!(u >= lo0 && u <= hi0 && v >= lo1 && v <= hi1)) return false;
      if (std::abs(du) + std::abs(dv) < 1e-13) {
        // A root on the patch's edge may converge a rounding error outside it; the test's
        // resolution (the contract's 1e-10 in parameter) admits it.
        const double slack = 1e-10;
        return u >= -slack && u <= 1.0 + slack && v >= -slack && v <= 1.0 + slack &&
               evaluate(g, u, v) > 0.0;
      }
    }
    return false;
  };

  // A cell is excluded only when a polynomial keeps its sign by more than its rounding
  // (a few ulps of its largest coefficient): a root on a cell's edge (a normal of the
  // patch boundary) must not be excluded by the sign of a rounding error.
  auto margin = [](const Bernstein2& p) {
    double largest = 0.0;
    for (double c : p.coefficients) largest = std::max(largest, std::abs(c));
    return 64.0 * std::numeric_limits<double>::epsilon() * largest;
  };
  const double m1 = margin(f1), m2 = margin(f2), mg = margin(g);
  auto keepsSign = [](const Bernstein2& p, double eps) {
    const Bounds b = bounds(p);
    return b.lo > eps || b.hi < -eps;
  };
  std::vector<MembershipCell> stack;
  stack.push_back({f1, f2, g, 0.0, 1.0, 0.0, 1.0, 0});
  int visited = 0;
  while (!stack.empty()) {
    MembershipCell cell = std::move(stack.back());
    stack.pop_back();
    if (++visited > 200000) return true;  // pathological: call it a normal (conservative)
    if (keepsSign(cell.f1, m1) || keepsSign(cell.f2, m2) || bounds(cell.g).hi < -mg) continue;
    const double width = cell.u1 - cell.u0;
    if (width <= 1.0 / 64.0) {
      const double reach = width;
      if (newton(0.5 * (cell.u0 + cell.u1), 0.5 * (cell.v0 + cell.v1), cell.u0 - reach,
                 cell.u1 + reach, cell.v0 - reach, cell.v1 + reach)) {
        return true;
      }
      // A root the Bernstein bounds cannot exclude but Newton does not reach: near a double
      // root (a fold). Keep subdividing to the resolution, then give the benefit of doubt.
      if (width <= 1e-9) return true;
    }
    const double um = 0.5 * (cell.u0 + cell.u1);
    const double vm = 0.5 * (cell.v0 + cell.v1);
    auto [f1l, f1r] = subdivideU(cell.f1, 0.5);
    auto [f2l, f2r] = subdivideU(cell.f2, 0.5);
    auto [gl, gr] = subdivideU(cell.g, 0.5);
    for (int side = 0; side < 2; ++side) {
      const Bernstein2& a = side == 0 ? f1l : f1r;
      const Bernstein2& b = side == 0 ? f2l : f2r;
      const Bernstein2& c = side == 0 ? gl : gr;
      const double u0 = side == 0 ? cell.u0 : um;
      const double u1 = side == 0 ? um : cell.u1;
      auto [a0, a1] = subdivideV(a, 0.5);
      auto [b0, b1] = subdivideV(b, 0.5);
      auto [c0, c1] = subdivideV(c, 0.5);
      stack.push_back({std::move(a0), std::move(b0), std::move(c0), u0, u1, cell.v0, vm, cell.depth + 1});
      stack.push_back({std::move(a1), std::move(b1), std::move(c1), u0, u1, vm, cell.v1, cell.depth + 1});
    }
  }
  return false;
}

bool patchHasNormal(const PatchData& data, const Vec3& m) { return hasNormal(data.normal, m); }

bool inOmega(const std::vector<PatchData>& patches, const Vec3& m) {
  for (const PatchData& p : patches) {
    if (patchHasNormal(p, m) || patchHasNormal(p, -m)) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------
// Normal curves, sampled to the tolerance where the polygon is used.
// ---------------------------------------------------------------------------------------

// Where Omega's boundary can lie, from a coarse map: the unit normals within `width` of
// its polygon (on the sphere; chords stand for angles, which they match to 1e-6 at these
// sizes). A curve of normals farther than that from the coarse boundary lies deep inside
// Omega, and its polygon may be as coarse as that map's (see symmetrizedGaussMap). A uniform
// grid of cells of side `reach` holds each boundary segment in every cell its box, grown by
// `reach`, meets, so one cell answers a query about any point in it.
class BoundaryBand {
 public:
  BoundaryBand(const std::vector<std::vector<Vec3>>& curves, double width)
      : width_(width), reach_(width + kMaxChord) {
    for (const auto& curve : curves) {
      for (std::size_t i = 0; i + 1 < curve.size(); ++i) {
        const Vec3 a = curve[i], b = curve[i + 1];
        const auto index = static_cast<std::uint32_t>(a_.size());
        a_.push_back(a);
        b_.push_back(b);
        const std::array<std::int64_t, 3> lo = cellOf(Vec3{std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)} - Vec3{reach_, reach_, reach_});
        const std::array<std::int64_t, 3> hi = cellOf(Vec3{std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)} + Vec3{reach_, reach_, reach_});
        for (std::int64_t x = lo[0]; x <= hi[0]; ++x) {
          for (std::int64_t y = lo[1]; y <= hi[1]; ++y) {
            for (std::int64_t z = lo[2]; z <= hi[2]; ++z) cells_[key({x, y, z})].push_back(index);
          }
        }
      }
    }
  }

  // Whether the curve piece sampled at n0, nm (its middle) and n1, or its antipode, may come
  // within the width of the boundary: judged at the middle with the chord's length added
  // (a piece longer than kMaxChord counts as near, to be halved further).
  bool near(const Vec3& n0, const Vec3& nm, const Vec3& n1) const {
    const double chord = std::max(norm(n0 - nm), norm(n1 - nm));
    if (chord > kMaxChord) return true;
    return within(nm, width_ + chord) || within(-nm, width_ + chord);
  }

 private:
  static constexpr double kMaxChord = 0.05;

  std::array<std::int64_t, 3> cellOf(const Vec3& p) const {
    return {static_cast<std::int64_t>(std::floor(p.x / reach_)),
            static_cast<std::int64_t>(std::floor(p.y / reach_)),
            static_cast<std::int64_t>(std::floor(p.z / reach_))};
  }
  static std::int64_t key(const std::array<std::int64_t, 3>& c) {
    // The three indices mixed into one key: a collision only costs extra distance tests.
    return (c[0] * 73856093) ^ (c[1] * 19349663) ^ (c[2] * 83492791);
  }
  bool within(const Vec3& p, double distance) const {
    const auto it = cells_.find(key(cellOf(p)));
    if (it == cells_.end()) return false;
    for (std::uint32_t i : it->second) {
      if (distanceToSegment(p, a_[i], b_[i]) <= distance) return true;
    }
    return false;
  }

  double width_;
  double reach_;
  std::vector<Vec3> a_, b_;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells_;
};

// Work bounds: halvings of one curve of normals (measured at 4e-7 degree on the paper's
// surfaces, ~100,000 boundary segments, and at 1e-6 degree on the whole teapot: at most
// 7,700 and 11,700), and quadtree cells of one patch (at most 88 and 100 there). Past them
// the map stops with an error naming the patch.
constexpr std::size_t kMaxCurveSamples = std::size_t{1} << 21;
constexpr std::size_t kMaxPatchCells = std::size_t{1} << 20;

// Samples normal curves n(s), s in [0, 1] (along a cell edge or a patch boundary), by
// halving until the polygon is within `tol` of the curve and no segment spans more than
// `maxStep` (so that a wiggle between samples is not missed). The polygon is used as
// straight segments in the stereographic plane of the pole frame, for n and for -n: a
// straight segment there is the image of a circle through the pole on the sphere (through
// the south pole for -n), whose geodesic curvature is the segment's distance h from the
// origin, so a segment close to the curve on the sphere can still stray from it by about
// h maxStep^2 / 8 in the plane: degrees at 0.5 degree, where maxStep is 32 degrees (a
// random two-patch surface lost a 0.9 degree deep sliver of normals that way). So the
// middle of each planar segment, for both signs, is mapped back onto the sphere and held
// within `tol` of the curve's point at the middle parameter, as the sphere chord's middle
// is. The rule depends on the end parameters only (through the normals there and at the
// middle), so two cells sampling a shared edge agree vertex for vertex.
struct NormalSampler {
  double tol;
  Rotation3 toPoleFrame;
  // Optional: away from `band` (deep inside Omega) the polygon is held within `coarseTol`.
  const BoundaryBand* band = nullptr;
  double coarseTol = 0.0;

  mutable std::size_t samples = 0;  // halvings of the current curve (see kMaxCurveSamples)

  double maxStep() const { return std::max(64.0 * tol, 0.05); }

  // How far (an angle on the sphere) the polygon edge n0-n1 strays from the curve, judged
  // at the middle: the angle from the curve's middle point nm to the edge's midpoint, on the
  // sphere and, mapped back onto the sphere, in the plane for n and -n.
  double deviation(const Vec3& n0, const Vec3& nm, const Vec3& n1) const {
    const Vec3 chord = n0 + n1;
    const double chordLength = norm(chord);
    if (!(chordLength > 0.0)) return std::numbers::pi;
    double worst = angleBetween(nm, chord / chordLength);
    for (double sign : {1.0, -1.0}) {
      const Vec3 r0 = apply(toPoleFrame, sign * n0);
      const Vec3 r1 = apply(toPoleFrame, sign * n1);
      // Within 1e-9 of the pole an end has no usable image (the pole itself none at all);
      // such a piece lies far outside the window the union works in (see clipToSquare's
      // caller), where only the sphere's measure is kept.
      auto nearPole = [](const Vec3& r) { return r.z > 0.0 && std::hypot(r.x, r.y) < 1e-9; };
      if (nearPole(r0) || nearPole(r1)) continue;
      // The whole angle, not the plane's distance over the local scale: two ends near the
      // pole on either side of it are joined by a segment through the middle of the plane,
      // far from the curve, whose middle is near the pole too.
      const Vec2 middle = 0.5 * (stereographic(r0) + stereographic(r1));
      worst = std::max(worst, angleBetween(apply(toPoleFrame, sign * nm), inverseStereographic(middle)));
    }
    return worst;
  }

  void refine(const std::function<Vec3(double)>& normalAt, double s0, double s1, const Vec3& n0,
              const Vec3& n1, int depth, std::vector<Vec3>& out,
              std::vector<double>* parameters) const {
    const double sm = 0.5 * (s0 + s1);
    const Vec3 nm = normalAt(sm);
    // The band is asked only when its answer decides: a deviation between tol and coarseTol.
    bool flat = angleBetween(n0, n1) <= maxStep();
    if (flat) {
      const double off = deviation(n0, nm, n1);
      flat = off <= tol || (band != nullptr && off <= coarseTol && !band->near(n0, nm, n1));
    }
    if (flat || depth >= 40) {
      out.push_back(n1);
      if (parameters != nullptr) parameters->push_back(s1);
      return;
    }
    // Bounded work: a curve the halving cannot resolve (rounding noise in a traced root, a
    // normal that turns without end) stops with an error, never an exponential run.
    if (++samples > kMaxCurveSamples) {
      throw Error(fmt::format("the Gauss map could not sample a curve of normals to the "
                              "tolerance within {} points (the normal turns too fast, or is "
                              "rounding noise, near parameter {} of a cell edge or a "
                              "parabolic line)", kMaxCurveSamples, sm));
    }
    refine(normalAt, s0, sm, n0, nm, depth + 1, out, parameters);
    refine(normalAt, sm, s1, nm, n1, depth + 1, out, parameters);
  }

  // The samples n(0), ..., n(1); their parameters s in `parameters` when given.
  std::vector<Vec3> curve(const std::function<Vec3(double)>& normalAt,
                          std::vector<double>* parameters = nullptr) const {
    samples = 0;
    std::vector<Vec3> out{normalAt(0.0)};
    if (parameters != nullptr) parameters->assign(1, 0.0);
    refine(normalAt, 0.0, 1.0, out.front(), normalAt(1.0), 0, out, parameters);
    return out;
  }
};

// ---------------------------------------------------------------------------------------
// The Gauss image as a union of cell images. A quadtree over each patch stops at cells of
// three kinds:
// - regular cells, where the curvature numerator keeps a strict sign (so the Gauss map is
//   a local diffeomorphism) and the normals vary by less than kRegularCellSpread: the image
//   is the region bounded by the images of the cell's four edges, sampled to the tolerance;
// - traced cells (traceAxis), crossed by one arc of a parabolic line that is a graph over
//   u or v: split along the traced arc into their K > 0 and K < 0 parts, each bounded by
//   its edges' images and the arc's (the fold's) image;
// - small fold cells, subdivided until their normals vary by less than the tolerance:
//   split along the chord between two crossings, else the convex hull of their normals.
// Neighbouring cells sample a shared edge vertex for vertex (see CellBuilder), so that their
// polygons meet without cracks. The union of the images, and of their antipodes, is Omega;
// its boundary lies on the images of the patch boundaries and of the parabolic lines (the
// folds), as the paper's method says, and the polygon union finds it.
// ---------------------------------------------------------------------------------------

constexpr double kRegularCellSpread = 0.5;  // radians
// The pole cell's normals spread over at least this many tolerances (when some regular cell's
// do): see the pole's choice in symmetrizedGaussMap.
constexpr double kPoleCellSpreadTolerances = 8.0;

// The coarse map of the band (see symmetrizedGaussMap): its tolerance (radians), used when
// the tolerance asked for is at least kCoarseBandFactor times finer; the band's half-width
// in coarse tolerances. The coarse boundary lies within its tolerance of the true one and a
// curve's coarse polygon within it of the curve: a curve farther than 4 coarse tolerances
// from the coarse boundary keeps a margin of 2 from the true one.
constexpr double kCoarseToleranceRad = 2e-4;
constexpr double kCoarseBandFactor = 16.0;
constexpr double kBandWidthTolerances = 4.0;

// A part of a cell where K keeps one sign: the image of its boundary, a loop (the image
// is the region it bounds, with the orientation of that sign).
struct SheetPart {
  std::vector<Vec3> normals;
  int curvatureSign = 0;
};

struct CellImage {
  std::vector<Vec3> normals;  // the images of the cell's boundary, a loop
  bool fold = false;          // a fold cell (see CellBuilder::split)
  /// A fold cell's parts for the sheets: its two sides of the parabolic line (or the whole
  /// cell where K keeps one sign on its boundary); empty when it takes the hull of `normals`
  /// instead. A regular cell is one part: `normals`, with `curvatureSign`.
  std::vector<SheetPart> parts;
  /// Whether the cell has the normal pole (first) and -pole (second): its image is then the
  /// outside of its projected loop.
  std::array<bool, 2> holdsPole{false, false};
  const PatchData* patch = nullptr;
  int curvatureSign = 0;      // regular cells: the sign of K (cells of one sign form a sheet)
};

struct Cell {
  double u0, u1, v0, v1;
  bool fold;
  Vec3 centre;
  double spread;
  int curvatureSign;  // regular cells: the sign of K on the cell
  // Fold cells whose parabolic line is traced (see traceAxis): 1 when K's zero set is a
  // graph v(u) on the cell, 2 when it is a graph u(v); 0 for the small fold cells.
  int traceAxis = 0;
  // Regular cells: the least angle from the centre normal to the normals at the cell's
  // corners and edge midpoints, about the radius of the widest disk about the centre inside
  // the image (a thin image, from a nearly developable patch, has it far below its spread).
  double innerRadius = 0.0;
};

// Whether the parabolic line crosses the cell (K's Bernstein coefficients `k` over it) as a
// single arc that can be traced as a graph: 1 when every coefficient difference along v has
// one strict sign (K is strictly monotone in v, so for each u at most one root: K's zero set
// is a union of graphs v(u), and no closed loop, which would have a point where K_v = 0)
// and the edges v = v0 and v = v1 show at most one sign variation each (at most one root
// each: the u where the graph exists, {K(u, v0) and K(u, v1) of opposite signs}, is then
// one interval, so there is one arc, or none); 2 likewise with u and v exchanged; else 0.
int traceAxis(const Bernstein2& k) {
  const int m = k.degreeU, n = k.degreeV;
  auto monotone = [&](bool alongV) {
    int sign = 0;
    for (int i = 0; i <= m - (alongV ? 0 : 1); ++i) {
      for (int j = 0; j <= n - (alongV ? 1 : 0); ++j) {
        const double d = alongV ? k.at(i, j + 1) - k.at(i, j) : k.at(i + 1, j) - k.at(i, j);
        const int s = d > 0.0 ? 1 : (d < 0.0 ? -1 : 0);
        if (s == 0 || (sign != 0 && s != sign)) return false;
        sign = s;
      }
    }
    return sign != 0;
  };
  auto edgeVariations = [&](bool alongU, int fixed) {
    Bernstein1 edge;
    if (alongU) {
      for (int i = 0; i <= m; ++i) edge.coefficients.push_back(k.at(i, fixed));
    } else {
      for (int j = 0; j <= n; ++j) edge.coefficients.push_back(k.at(fixed, j));
    }
    return signVariations(edge);
  };
  if (n >= 1 && monotone(true) && edgeVariations(true, 0) <= 1 && edgeVariations(true, n) <= 1) {
    return 1;
  }
  if (m >= 1 && monotone(false) && edgeVariations(false, 0) <= 1 && edgeVariations(false, m) <= 1) {
    return 2;
  }
  return 0;
}

// Cells of one patch, and the images of their boundaries. Every cell edge is cut at every
// cell corner that lies on it (the quadtree's T-junctions), and each elementary piece is
// sampled by a rule that depends only on its two end parameters: two cells sharing an edge
// then share its image polygon vertex for vertex, and their images meet without cracks or
// overlaps (which the polygon union handles at little cost).
struct CellBuilder {
  const PatchData& data;
  double tol;
  int maxDepth;  // GaussMapOptions::maxCellDepth
  std::vector<Cell> cells;
  // A direction (and its antipode) no traced cell may hold: the pole, whose image is far out
  // in the plane (see symmetrizedGaussMap); such a cell is subdivided instead.
  const Vec3* avoid = nullptr;
  // Cells not to trace (their edges did not show two crossings in an earlier run).
  std::set<std::array<double, 4>> noTrace;

  // Whether the cell has the normal m (first) and -m (second): decided exactly in Bernstein
  // form where its sampled normals come within twice their spread of it.
  std::array<bool, 2> holds(double u0, double u1, double v0, double v1, const Vec3& centre,
                            double spread, const Vec3& m) const {
    std::array<bool, 2> out{false, false};
    for (std::size_t k = 0; k < 2; ++k) {
      const Vec3 target = k == 0 ? m : -m;
      if (angleBetween(centre, target) > 2.0 * spread + tol) continue;
      std::array<Bernstein2, 3> local;
      for (std::size_t i = 0; i < 3; ++i) local[i] = restrictTo(data.normal[i], u0, u1, v0, v1);
      out[k] = hasNormal(local, target);
    }
    return out;
  }
  bool holdsEither(const Cell& c, const Vec3& m) const {
    const std::array<bool, 2> h = holds(c.u0, c.u1, c.v0, c.v1, c.centre, c.spread, m);
    return h[0] || h[1];
  }

  Vec3 normalAt(double u, double v) const { return unitNormal(*data.patch, u, v); }

  // The normals on a cell's 3 x 3 grid of corners, edge midpoints and centre: grid[i][j]
  // at (u0 + i (u1 - u0) / 2, v0 + j (v1 - v0) / 2). A child cell's corners are points of
  // its parent's grid (dyadic parameters: bitwise the same), so only five are new.
  using NormalGrid = std::array<std::array<Vec3, 3>, 3>;

  void run() {
    NormalGrid grid;
    for (int i = 0; i <= 2; ++i) {
      for (int j = 0; j <= 2; ++j) grid[i][j] = normalAt(0.5 * i, 0.5 * j);
    }
    visit(data.curvature, 0.0, 1.0, 0.0, 1.0, 0, grid);
  }

  void visit(const Bernstein2& k, double u0, double u1, double v0, double v1, int depth,
             const NormalGrid& grid) {
    checkCancelled();
    const Vec3& centre = grid[1][1];
    double spread = 0.0;
    for (int i = 0; i <= 2; ++i) {
      for (int j = 0; j <= 2; ++j) spread = std::max(spread, angleBetween(centre, grid[i][j]));
    }
    if (strictSign(k) && spread <= kRegularCellSpread) {
      double inner = spread;
      for (int i = 0; i <= 2; ++i) {
        for (int j = 0; j <= 2; ++j) {
          if (i != 1 || j != 1) inner = std::min(inner, angleBetween(centre, grid[i][j]));
        }
      }
      cells.push_back({u0, u1, v0, v1, false, centre, spread, bounds(k).lo > 0.0 ? 1 : -1, 0, inner});
      return;
    }
    if (spread <= kRegularCellSpread) {
      const Cell traced{u0, u1, v0, v1, true, centre, spread, 0, traceAxis(k)};
      if (traced.traceAxis != 0 && !noTrace.contains(boundsOf(traced)) &&
          !(avoid != nullptr && holdsEither(traced, *avoid))) {
        cells.push_back(traced);
        return;
      }
    }
    if (spread <= tol || depth >= maxDepth) {
      cells.push_back({u0, u1, v0, v1, true, centre, spread, 0});
      return;
    }
    if (cells.size() >= kMaxPatchCells) {
      throw Error(fmt::format("the Gauss map's quadtree reached {} cells without resolving the "
                              "parabolic lines near (u, v) = ({}, {})",
                              kMaxPatchCells, 0.5 * (u0 + u1), 0.5 * (v0 + v1)));
    }
    const double um = 0.5 * (u0 + u1);
    const double vm = 0.5 * (v0 + v1);
    auto [left, right] = subdivideU(k, 0.5);
    auto [ll, lr] = subdivideV(left, 0.5);
    auto [rl, rr] = subdivideV(right, 0.5);
    // The child (a, b): u in [u0 + a (u1 - u0) / 2, ...], v likewise with b.
    auto child = [&](int a, int b, double cu0, double cu1, double cv0, double cv1) {
      NormalGrid g;
      for (int i = 0; i <= 2; ++i) {
        for (int j = 0; j <= 2; ++j) {
          if (i % 2 == 0 && j % 2 == 0) {
            g[i][j] = grid[a + i / 2][b + j / 2];
          } else {
            g[i][j] = normalAt(cu0 + 0.5 * i * (cu1 - cu0), cv0 + 0.5 * j * (cv1 - cv0));
          }
        }
      }
      return g;
    };
    visit(ll, u0, um, v0, vm, depth + 1, child(0, 0, u0, um, v0, vm));
    visit(lr, u0, um, vm, v1, depth + 1, child(0, 1, u0, um, vm, v1));
    visit(rl, um, u1, v0, vm, depth + 1, child(1, 0, um, u1, v0, vm));
    visit(rr, um, u1, vm, v1, depth + 1, child(1, 1, um, u1, vm, v1));
  }

  // Normals along the segment from (ua, va) to (ub, vb) (a piece of a cell edge), both ends
  // included, sampled to the tolerance by halving (deterministic in the end points).
  std::vector<Vec3> sampleEdge(const NormalSampler& sampler, double ua, double va, double ub,
                               double vb, std::vector<double>* parameters = nullptr) const {
    return sampler.curve(
        [&](double s) { return normalAt(ua + s * (ub - ua), va + s * (vb - va)); }, parameters);
  }

  // The Gaussian curvature numerator (r_uu . N)(r_vv . N) - (r_uv . N)^2 at (u, v), from the
  // patch's derivatives: the polynomial `data.curvature`, evaluated cheaply.
  double curvatureAt(double u, double v) const {
    // With edge factors split off, the polynomial itself: the numerator divided by them
    // would be noise beside those edges.
    if (data.curvaturePowers.any()) return evaluate(data.curvature, u, v);
    return gaussianCurvatureNumeratorAt(*data.patch, u, v);
  }

  // The sign of a value of K, as a sample records it (0 on a parabolic line).
  static signed char signOf(double k) { return k > 0.0 ? 1 : (k < 0.0 ? -1 : 0); }

  // The root of K on the segment from p0 to p1, where K has opposite signs f0 and f1 at the
  // ends, as the parameter s in (0, 1), to `width`: regula falsi with the Anderson-Bjorck
  // modification (bracketed; about five evaluations where Illinois took ten on the traced
  // arcs: the retained end's value is scaled by 1 - f_new / f_old, not by a half, when that
  // is positive).
  double curvatureRoot(UV p0, UV p1, double f0, double f1, double width = 1e-15) const {
    auto at = [&](double s) { return curvatureAt(p0.u + s * (p1.u - p0.u), p0.v + s * (p1.v - p0.v)); };
    double s0 = 0.0, s1 = 1.0;
    double root = 0.5;
    int side = 0;
    for (int it = 0; it < 100 && s1 - s0 > width; ++it) {
      root = (s0 * f1 - s1 * f0) / (f1 - f0);
      if (!(root > s0 && root < s1)) root = 0.5 * (s0 + s1);
      const double f = at(root);
      if (f == 0.0) break;
      if ((f < 0.0) == (f0 < 0.0)) {
        // The s1 end is retained: scaled when it was retained last time too.
        const double scale = 1.0 - f / f0;
        if (side == -1) f1 *= scale > 0.0 ? scale : 0.5;
        s0 = root, f0 = f;
        side = -1;
      } else {
        const double scale = 1.0 - f / f1;
        if (side == 1) f0 *= scale > 0.0 ? scale : 0.5;
        s1 = root, f1 = f;
        side = 1;
      }
    }
    return root;
  }

  // Samples of a cell-edge piece with the sign of K at each and their parameters, and the
  // points where the piece crosses a parabolic line (sign 0) inserted between samples of
  // opposite sign.
  struct EdgeSamples {
    std::vector<Vec3> normals;
    std::vector<signed char> signs;
    std::vector<UV> where;
  };

  // The piece from a to b. A regular cell's K has a strict sign on its closed cell, so a
  // piece it asks for takes that sign (`knownSign`) without evaluation; a fold cell's piece
  // (knownSign 0) is evaluated. Either way the result depends on the piece alone, so the
  // two cells sharing it agree. One crossing is found between two samples of opposite
  // sign: a traced cell's edges have at most one root each (see traceAxis), and a small
  // fold cell's edges are shorter than the tolerance.
  EdgeSamples sampleEdgeWithSigns(const NormalSampler& sampler, UV a, UV b, int knownSign) const {
    EdgeSamples out;
    std::vector<double> parameters;
    const std::vector<Vec3> normals = sampleEdge(sampler, a.u, a.v, b.u, b.v, &parameters);
    auto pointAt = [&](double s) { return UV{a.u + s * (b.u - a.u), a.v + s * (b.v - a.v)}; };
    if (knownSign != 0) {
      out.normals = normals;
      out.signs.assign(normals.size(), static_cast<signed char>(knownSign));
      for (double s : parameters) out.where.push_back(pointAt(s));
      return out;
    }
    std::vector<double> values(parameters.size());
    for (std::size_t i = 0; i < parameters.size(); ++i) {
      const UV p = pointAt(parameters[i]);
      values[i] = curvatureAt(p.u, p.v);
    }
    for (std::size_t i = 0; i < parameters.size(); ++i) {
      if (i > 0 && values[i - 1] * values[i] < 0.0) {
        const UV p0 = pointAt(parameters[i - 1]), p1 = pointAt(parameters[i]);
        const double t = curvatureRoot(p0, p1, values[i - 1], values[i]);
        const UV root{p0.u + t * (p1.u - p0.u), p0.v + t * (p1.v - p0.v)};
        out.normals.push_back(normalAt(root.u, root.v));
        out.signs.push_back(0);
        out.where.push_back(root);
      }
      out.normals.push_back(normals[i]);
      out.signs.push_back(signOf(values[i]));
      out.where.push_back(pointAt(parameters[i]));
    }
    return out;
  }

  // The piece from a to b at its ends alone, with its crossing of a parabolic line between
  // them when K's signs there differ (a traced cell's edge has at most one root, see
  // traceAxis; a regular cell's none): for pieces inside the sheets (see images).
  EdgeSamples sampleEnds(UV a, UV b, int knownSign) const {
    EdgeSamples out;
    const double ka = knownSign != 0 ? knownSign : curvatureAt(a.u, a.v);
    const double kb = knownSign != 0 ? knownSign : curvatureAt(b.u, b.v);
    out.normals.push_back(normalAt(a.u, a.v));
    out.signs.push_back(signOf(ka));
    out.where.push_back(a);
    if (ka * kb < 0.0) {
      const double t = curvatureRoot(a, b, ka, kb);
      const UV root{a.u + t * (b.u - a.u), a.v + t * (b.v - a.v)};
      out.normals.push_back(normalAt(root.u, root.v));
      out.signs.push_back(0);
      out.where.push_back(root);
    }
    out.normals.push_back(normalAt(b.u, b.v));
    out.signs.push_back(signOf(kb));
    out.where.push_back(b);
    return out;
  }

  // The normals along the parabolic line of a traced cell from its crossing a to its
  // crossing b (both included, bitwise those of the edges), sampled to the tolerance: the
  // line is the graph v(u) (traceAxis 1) or u(v) (2), each point the one root of K on the
  // cell's chord across at that u (or v).
  std::vector<Vec3> traceParabolicLine(const Cell& c, UV a, UV b, const NormalSampler& sampler) const {
    const bool graphOfU = c.traceAxis == 1;
    const double from = graphOfU ? a.u : a.v, to = graphOfU ? b.u : b.v;
    if (from == to) return {normalAt(a.u, a.v), normalAt(b.u, b.v)};
    // The root on each chord is bracketed first near the previous chord's (the line is a
    // graph, so it moves continuously across the chords), the bracket widened eightfold
    // until K changes sign across it, up to the whole chord: a narrow bracket saves half
    // the curvature evaluations.
    double previous = -1.0;  // the previous chord's root (parameter along the chord), if any
    auto pointAt = [&](double s) -> UV {
      if (s == 0.0) return a;
      if (s == 1.0) return b;
      const double t = from + s * (to - from);
      const UV lo = graphOfU ? UV{t, c.v0} : UV{c.u0, t};
      const UV hi = graphOfU ? UV{t, c.v1} : UV{c.u1, t};
      auto along = [&](double r) { return UV{lo.u + r * (hi.u - lo.u), lo.v + r * (hi.v - lo.v)}; };
      auto curvature = [&](double r) {
        const UV p = along(r);
        return curvatureAt(p.u, p.v);
      };
      for (double halfWidth = 1.0 / 64.0; previous >= 0.0 && halfWidth < 0.5; halfWidth *= 8.0) {
        const double r0 = std::max(0.0, previous - halfWidth), r1 = std::min(1.0, previous + halfWidth);
        const double f0 = curvature(r0), f1 = curvature(r1);
        if (f0 * f1 < 0.0) {
          const double r = r0 + (r1 - r0) * curvatureRoot(along(r0), along(r1), f0, f1, 1e-15 / (r1 - r0));
          previous = r;
          return along(r);
        }
      }
      const double f0 = curvature(0.0), f1 = curvature(1.0);
      double r = 0.0;
      if (f0 * f1 < 0.0) {
        r = curvatureRoot(lo, hi, f0, f1);
        previous = r;
      } else {
        r = std::abs(f0) <= std::abs(f1) ? 0.0 : 1.0;  // rounding at the arc's ends
      }
      return along(r);
    };
    return sampler.curve([&](double s) {
      const UV p = pointAt(s);
      return normalAt(p.u, p.v);
    });
  }

  // A fold cell's boundary loop (normals with the sign of K at each, 0 on a parabolic line,
  // and their parameters) split into the parts where K keeps one sign: with no crossing and
  // one sign throughout, the whole cell; with two crossings, the two sides, each closed by
  // the parabolic line between the crossings: traced (traceAxis), or for a small fold cell
  // (whose normals vary by less than the tolerance) the chord. Anything else (several
  // lines, K = 0 along an edge): no parts, and the cell takes the hull of its normals.
  // `crossings` receives the two crossings of a split cell.
  std::vector<SheetPart> split(const Cell& c, const NormalSampler& sampler,
                               const std::vector<Vec3>& loop, const std::vector<signed char>& signs,
                               const std::vector<UV>& where, std::pair<UV, UV>* crossings) const {
    std::vector<std::size_t> zeros;
    for (std::size_t i = 0; i < signs.size(); ++i) {
      if (signs[i] == 0) zeros.push_back(i);
    }
    auto uniform = [&](std::size_t from, std::size_t count) -> int {
      // The sign shared by `count` samples from `from` on (cyclically), or 0.
      if (count == 0) return 0;
      const int first = signs[from % signs.size()];
      for (std::size_t k = 1; k < count; ++k) {
        if (signs[(from + k) % signs.size()] != first) return 0;
      }
      return first;
    };
    if (zeros.empty()) {
      const int sign = uniform(0, signs.size());
      if (sign == 0) return {};
      return {SheetPart{loop, sign}};
    }
    if (zeros.size() != 2) return {};
    const std::size_t a = zeros[0], b = zeros[1], n = loop.size();
    const int first = uniform(a + 1, b - a - 1);
    const int second = uniform(b + 1, n - (b - a) - 1);
    if (first == 0 || second == 0 || first == second) return {};
    // The line from a to b, ends included (for a small fold cell, the chord: its ends).
    const std::vector<Vec3> line = c.traceAxis != 0
                                       ? traceParabolicLine(c, where[a], where[b], sampler)
                                       : std::vector<Vec3>{loop[a], loop[b]};
    std::vector<SheetPart> parts(2);
    for (std::size_t k = a; k <= b; ++k) parts[0].normals.push_back(loop[k]);
    for (std::size_t k = line.size() - 2; k >= 1; --k) parts[0].normals.push_back(line[k]);
    for (std::size_t k = b; k <= a + n; ++k) parts[1].normals.push_back(loop[k % n]);
    for (std::size_t k = 1; k + 1 < line.size(); ++k) parts[1].normals.push_back(line[k]);
    parts[0].curvatureSign = first;
    parts[1].curvatureSign = second;
    if (crossings != nullptr) *crossings = {where[a], where[b]};
    return parts;
  }

  struct ImageStats {
    std::size_t parabolicLines = 0;  // connected pieces of parabolic line (chains of arcs)
    std::size_t tracedCells = 0;     // fold cells whose line was traced
    std::size_t untracedCells = 0;   // traced cells whose edges did not show two crossings,
                                     // subdivided in a rerun (counted over every run)
  };

  // The number of connected chains among parabolic-line arcs given by their end points
  // (arcs of neighbouring cells meet at bitwise the same crossing).
  static std::size_t chainCount(const std::vector<std::pair<UV, UV>>& arcs) {
    std::map<std::pair<double, double>, std::size_t> ids;
    std::vector<std::size_t> parent;
    auto id = [&](const UV& p) {
      auto [it, inserted] = ids.emplace(std::pair{p.u, p.v}, parent.size());
      if (inserted) parent.push_back(parent.size());
      return it->second;
    };
    auto find = [&](std::size_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    std::size_t components = 0;
    for (const auto& [a, b] : arcs) {
      const std::size_t ia = id(a);
      const std::size_t ib = id(b);
      const std::size_t ra = find(ia), rb = find(ib);
      if (ra != rb) parent[ra] = rb;
    }
    for (std::size_t x = 0; x < parent.size(); ++x) components += find(x) == x ? 1 : 0;
    return components;
  }

  using CellBounds = std::array<double, 4>;
  static CellBounds boundsOf(const Cell& c) { return {c.u0, c.u1, c.v0, c.v1}; }

  // The cells' images, their edges sampled by `sampler` (whose frame is the pole's), or by
  // `inner` (the same with the coarse band, see BoundaryBand) off the patch's seams.
  // `untraceable` receives the traced cells whose edges did not show their arc's two ends
  // (rounding at a crossing), to be subdivided in a new run.
  std::vector<CellImage> images(const NormalSampler& sampler, const NormalSampler& inner,
                                ImageStats& stats, std::vector<CellBounds>& untraceable) const {
    std::vector<std::pair<UV, UV>> arcs;
    for (const Cell& c : cells) stats.tracedCells += c.traceAxis != 0 ? 1 : 0;
    // Corners on every vertical line u = c and horizontal line v = c (dyadic: exact keys).
    std::map<double, std::vector<double>> onU;  // u -> v's of corners
    std::map<double, std::vector<double>> onV;  // v -> u's of corners
    for (const Cell& c : cells) {
      for (double u : {c.u0, c.u1}) {
        for (double v : {c.v0, c.v1}) onU[u].push_back(v), onV[v].push_back(u);
      }
    }
    for (auto* index : {&onU, &onV}) {
      for (auto& [unused, values] : *index) {
        std::sort(values.begin(), values.end());
        values.erase(std::unique(values.begin(), values.end()), values.end());
      }
    }
    // The elementary pieces of a cell's edges, in the loop's order: bottom (v = v0, u up),
    // right (u = u1, v up), top (v = v1, u down), left (u = u0, v down), each cut at every
    // corner on it (its cut points on the line, increasing, taken forward or backward).
    struct EdgePiece {
      bool alongU;      // along u at v = fixed, or along v at u = fixed
      double fixed, t0, t1;  // t0 < t1
      bool backward;    // the loop runs it from t1 to t0
    };
    auto edgePieces = [&](const Cell& c) {
      std::vector<EdgePiece> out;
      auto add = [&](const std::vector<double>& values, bool alongU, double fixed, double a,
                     double b, bool backward) {
        std::vector<double> ts;
        for (auto it = std::lower_bound(values.begin(), values.end(), a);
             it != values.end() && *it <= b; ++it) {
          ts.push_back(*it);
        }
        const std::size_t first = out.size();
        for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
          out.push_back({alongU, fixed, ts[i], ts[i + 1], backward});
        }
        if (backward) std::reverse(out.begin() + static_cast<std::ptrdiff_t>(first), out.end());
      };
      add(onV.at(c.v0), true, c.v0, c.u0, c.u1, false);
      add(onU.at(c.u1), false, c.u1, c.v0, c.v1, false);
      add(onV.at(c.v1), true, c.v1, c.u0, c.u1, true);
      add(onU.at(c.u0), false, c.u0, c.v0, c.v1, true);
      return out;
    };
    auto key = [](const EdgePiece& e) {
      return std::array<double, 3>{e.alongU ? e.fixed : -1.0 - e.fixed, e.t0, e.t1};
    };
    // A piece on a patch edge that may be a seam (see PatchData::seam).
    auto onSeam = [&](const EdgePiece& e) {
      if (e.fixed != 0.0 && e.fixed != 1.0) return false;
      return e.alongU ? data.seam[e.fixed == 0.0 ? 0 : 2] : data.seam[e.fixed == 0.0 ? 3 : 1];
    };
    // Which cells hold +-pole (see `avoid`), decided once: for their pieces' sampling below
    // and for the union, which takes such a cell's image as the outside of its loop.
    std::vector<std::array<bool, 2>> poleHeld(cells.size(), {false, false});
    if (avoid != nullptr) {
      for (std::size_t i = 0; i < cells.size(); ++i) {
        const Cell& c = cells[i];
        poleHeld[i] = holds(c.u0, c.u1, c.v0, c.v1, c.centre, c.spread, *avoid);
      }
    }
    // An edge piece shared by two cells that both join their sheets (regular or traced,
    // neither holding +-pole) lies inside those sheets: the two cells run it opposite ways,
    // and each of its stretches of one sign of K (the whole piece, or the two sides of its
    // one crossing) belongs to the same sheet in both, so mergeSheet cancels it whatever its
    // polygon, the sliver between polygon and curve counting for one cell as much as against
    // the other. Such a piece is sampled at its ends and crossing alone: only the patch
    // boundary and the parabolic lines, which bound the sheets, are sampled to the tolerance.
    // (Small fold cells may take the hull of their normals, and a cell holding the pole keeps
    // its image as the outside of its own loop: their pieces are sampled to the tolerance.)
    struct PieceUse {
      int users = 0;
      bool joinSheets = true;  // every user joins its sheet
      int sign = 0;            // the users' common sign of K when all are regular, or 0
    };
    std::map<std::array<double, 3>, PieceUse> uses;
    std::vector<std::vector<EdgePiece>> cellPieces(cells.size());
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const Cell& c = cells[i];
      const bool joins = (!c.fold || c.traceAxis != 0) && !poleHeld[i][0] && !poleHeld[i][1];
      const int sign = c.fold ? 0 : c.curvatureSign;
      cellPieces[i] = edgePieces(c);
      for (const EdgePiece& e : cellPieces[i]) {
        PieceUse& use = uses[key(e)];
        use.sign = use.users == 0 || use.sign == sign ? sign : 0;
        use.joinSheets = use.joinSheets && joins;
        ++use.users;
      }
    }
    // Each elementary piece is shared by at most two cells (which run it opposite ways):
    // sampled once, in increasing parameter, and kept until its second use.
    std::map<std::array<double, 3>, EdgeSamples> pieces;
    std::vector<CellImage> out;
    out.reserve(cells.size());
    for (std::size_t index = 0; index < cells.size(); ++index) {
      const Cell& c = cells[index];
      CellImage image;
      image.fold = c.fold;
      image.holdsPole = poleHeld[index];
      image.patch = &data;
      image.curvatureSign = c.curvatureSign;
      auto& loop = image.normals;
      std::vector<signed char> signs;
      std::vector<UV> where;
      for (const EdgePiece& e : cellPieces[index]) {
        const std::array<double, 3> pieceKey = key(e);
        EdgeSamples samples;
        if (auto it = pieces.find(pieceKey); it != pieces.end()) {
          samples = std::move(it->second);
          pieces.erase(it);
        } else {
          const UV a = e.alongU ? UV{e.t0, e.fixed} : UV{e.fixed, e.t0};
          const UV b = e.alongU ? UV{e.t1, e.fixed} : UV{e.fixed, e.t1};
          const PieceUse& use = uses.at(pieceKey);
          if (use.users == 2 && use.joinSheets) {
            samples = sampleEnds(a, b, use.sign);
          } else {
            samples = sampleEdgeWithSigns(onSeam(e) ? sampler : inner, a, b, c.curvatureSign);
          }
          pieces.emplace(pieceKey, samples);
        }
        // Emitted from its start in the loop's sense, its last sample left to the next piece.
        const std::size_t n = samples.normals.size();
        for (std::size_t j = 0; j + 1 < n; ++j) {
          const std::size_t k = e.backward ? n - 1 - j : j;
          loop.push_back(samples.normals[k]);
          signs.push_back(samples.signs[k]);
          where.push_back(samples.where[k]);
        }
      }
      if (c.fold) {
        std::pair<UV, UV> crossing;
        image.parts = split(c, inner, loop, signs, where, &crossing);
        if (image.parts.size() == 2) arcs.emplace_back(crossing.first, crossing.second);
        if (image.parts.empty() && c.traceAxis != 0) untraceable.push_back(boundsOf(c));
      }
      out.push_back(std::move(image));
    }
    stats.parabolicLines += chainCount(arcs);
    return out;
  }
};

// The union runs on Clipper's integer grid (libpolyclipping, Clipper 6): coordinates below
// 2^30 in magnitude keep its products in 64 bits.
using IntPoint = ClipperLib::IntPoint;
using IntLoop = ClipperLib::Path;
using IntLoops = ClipperLib::Paths;
// Omega's union: more pieces than this are united in groups of kUnionGroup first (a tree).
constexpr std::size_t kOneSweepPieces = 512;
constexpr std::size_t kUnionGroup = 16;

// Andrew's monotone chain: the convex hull of a point set, counter-clockwise.
std::vector<Vec2> convexHull(std::vector<Vec2> points) {
  std::sort(points.begin(), points.end(),
            [](const Vec2& a, const Vec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  if (points.size() < 3) return points;
  std::vector<Vec2> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross(hull[k - 1] - hull[k - 2], points[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// The polygon `loop` clipped to the square |x|, |y| <= half (Sutherland-Hodgman, one side
// at a time): its region meets the square in the region of the result, with the same
// orientation, plus zero-width bridges along the square's sides. An edge crossing a side is
// cut at a point computed from its end inside the square (whichever way the edge runs), so
// two cells sharing an edge cut it at bitwise the same point and still cancel in mergeSheet.
std::vector<Vec2> clipToSquare(std::vector<Vec2> loop, double half) {
  // Side k keeps the points with coordinate(k) * direction(k) <= half.
  for (int side = 0; side < 4 && !loop.empty(); ++side) {
    const bool alongX = side < 2;
    const double sense = side % 2 == 0 ? 1.0 : -1.0;
    auto coordinate = [&](const Vec2& p) { return sense * (alongX ? p.x : p.y); };
    auto crossing = [&](const Vec2& in, const Vec2& out) {
      const double t = (half - coordinate(in)) / (coordinate(out) - coordinate(in));
      Vec2 q = in + t * (out - in);
      (alongX ? q.x : q.y) = sense * half;  // exactly on the side
      return q;
    };
    std::vector<Vec2> kept;
    kept.reserve(loop.size() + 4);
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const Vec2& a = loop[i == 0 ? loop.size() - 1 : i - 1];
      const Vec2& b = loop[i];
      const bool aIn = coordinate(a) <= half;
      const bool bIn = coordinate(b) <= half;
      if (aIn != bIn) kept.push_back(aIn ? crossing(a, b) : crossing(b, a));
      if (bIn) kept.push_back(b);
    }
    loop = std::move(kept);
  }
  return loop;
}

// A thin strip of the sphere standing for a piece of a curve image (a developable patch's
// normals): the points within `halfWidth` of the great-circle arc a-b (a point when b = a),
// as a loop of sphere points around it, two half circles joined by the arc's offsets. The
// half circles' polygons are circumscribed (their vertices a little farther out than
// halfWidth) so that their chords still keep halfWidth. `reach` is the angle from the arc
// to the loop's vertices, which decides whether the strip holds the pole.
struct ThinStrip {
  std::vector<Vec3> loop;
  double reach = 0.0;
};

ThinStrip thinStrip(const Vec3& a, const Vec3& b, double halfWidth) {
  constexpr int kHalf = 8;  // chords per half circle
  ThinStrip strip;
  strip.reach = halfWidth / std::cos(std::numbers::pi / (2.0 * kHalf));
  Vec3 side = cross(a, b);
  Vec3 ta, tb;  // tangents along the arc: at a towards b, at b away from a
  if (norm(side) > 1e-12) {
    side = normalized(side);
    ta = cross(side, a);
    tb = cross(side, b);
  } else {
    const Vec3 helper = std::abs(a.x) < 0.6 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
    side = normalized(cross(a, helper));
    ta = tb = cross(side, a);
  }
  auto around = [&](const Vec3& centre, const Vec3& forward, double phi) {
    const Vec3 d = std::cos(phi) * forward + std::sin(phi) * side;
    return normalized(std::cos(strip.reach) * centre + std::sin(strip.reach) * d);
  };
  for (int k = 0; k <= kHalf; ++k) {  // around b, from -side through its forward tangent
    strip.loop.push_back(around(b, tb, -0.5 * std::numbers::pi + std::numbers::pi * k / kHalf));
  }
  for (int k = 0; k <= kHalf; ++k) {  // around a, from +side through its backward tangent
    strip.loop.push_back(around(a, ta, 0.5 * std::numbers::pi + std::numbers::pi * k / kHalf));
  }
  return strip;
}

// The angle from p to the great-circle arc a-b (shorter than a half circle).
double angleToArc(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 side = cross(a, b);
  const double length = norm(side);
  if (length > 1e-12) {
    const Vec3 n = side / length;
    // p's foot on the arc's great circle lies within the arc when p is ahead of a (along
    // the arc's tangent n x a there) and behind b (along b x n, its backward tangent).
    if (dot(cross(n, a), p) >= 0.0 && dot(cross(b, n), p) >= 0.0) {
      return std::asin(std::min(1.0, std::abs(dot(n, p))));
    }
  }
  return std::min(angleBetween(p, a), angleBetween(p, b));
}

// Twice the signed area of an integer loop (positive counter-clockwise), in double.
double signedArea2(const IntLoop& loop) {
  double sum = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const IntPoint& a = loop[i];
    const IntPoint& b = loop[(i + 1) % loop.size()];
    sum += static_cast<double>(a.X) * static_cast<double>(b.Y) - static_cast<double>(b.X) * static_cast<double>(a.Y);
  }
  return sum;
}

// The union of one sheet's cell polygons (all of one orientation, sharing vertices exactly):
// the directed edges left after each edge met in both directions cancels, walked into loops.
// Their winding number (each edge counted by its own direction) is the cells' summed: where
// the walk joins pieces of opposite sense at a vertex (a hole touching the outline), the
// loop's parts still add and subtract as the cells did.
IntLoops mergeSheet(const IntLoops& cells) {
  // Every edge under its undirected key (the lesser end first) with +1 when it runs from the
  // lesser end, -1 when it runs back: sorted, each key's sum is its net multiplicity.
  struct Edge {
    IntPoint from, to;
    int count;  // +1 or -1, see above
  };
  auto less = [](const IntPoint& a, const IntPoint& b) {
    return a.X < b.X || (a.X == b.X && a.Y < b.Y);
  };
  std::vector<Edge> edges;
  for (const IntLoop& points : cells) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const IntPoint& a = points[i];
      const IntPoint& b = points[(i + 1) % points.size()];
      if (a == b) continue;
      edges.push_back(less(a, b) ? Edge{a, b, 1} : Edge{b, a, -1});
    }
  }
  auto byKey = [&](const Edge& e, const Edge& f) {
    return less(e.from, f.from) || (e.from == f.from && less(e.to, f.to));
  };
  std::sort(edges.begin(), edges.end(), byKey);
  // The directed edges left, one per unit of net multiplicity, sorted by their start.
  struct Directed {
    IntPoint from, to;
    bool used = false;
  };
  std::vector<Directed> left;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    int net = 0;
    while (j < edges.size() && edges[j].from == edges[i].from && edges[j].to == edges[i].to) {
      net += edges[j++].count;
    }
    for (int k = 0; k < std::abs(net); ++k) {
      left.push_back(net > 0 ? Directed{edges[i].from, edges[i].to} : Directed{edges[i].to, edges[i].from});
    }
    i = j;
  }
  edges.clear();
  std::sort(left.begin(), left.end(), [&](const Directed& e, const Directed& f) { return less(e.from, f.from); });
  // Walk them into loops: from each unused edge, on along an unused edge leaving its end,
  // until back at the start.
  auto unusedFrom = [&](const IntPoint& p) -> Directed* {
    auto it = std::lower_bound(left.begin(), left.end(), p,
                               [&](const Directed& e, const IntPoint& q) { return less(e.from, q); });
    for (; it != left.end() && it->from == p; ++it) {
      if (!it->used) return &*it;
    }
    return nullptr;
  };
  IntLoops out;
  for (Directed& first : left) {
    if (first.used) continue;
    first.used = true;
    IntLoop loop{first.to};
    while (!(loop.back() == first.from)) {
      Directed* next = unusedFrom(loop.back());
      if (next == nullptr) break;
      next->used = true;
      loop.push_back(next->to);
    }
    if (loop.size() >= 3) out.push_back(std::move(loop));
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// symmetrizedGaussMap's stages, in the order it runs them.

void validateOptions(const GaussMapOptions& options) {
  const double tol = options.toleranceRad;
  if (!(tol > 0.0) || !std::isfinite(tol)) {
    throw Error(fmt::format("the Gauss map tolerance must be a positive angle, got {} rad", tol));
  }
  if (tol < kMinGaussMapToleranceRad) {
    throw Error(fmt::format("the Gauss map tolerance {} rad is finer than its integer grid "
                            "resolves; the least is {} rad ({} degree)", tol,
                            kMinGaussMapToleranceRad,
                            kMinGaussMapToleranceRad * 180.0 / std::numbers::pi));
  }
  if (options.maxCellDepth < 1 || options.maxCellDepth > 40) {
    throw Error(fmt::format("the Gauss map's deepest quadtree level must be 1 .. 40, got {}",
                            options.maxCellDepth));
  }
}

// Runs one patch's quadtree or sampling; its errors name the patch.
template <typename Work>
void inPatch(const PatchData& data, const Work& work) {
  try {
    work();
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& e) {
    throw Error(fmt::format("patches[{}]: {}", data.index, e.what()));
  }
}

// The cells of every curved patch, and the patches whose image is a curve (a developable
// patch has no regular cell: its image is the image of its boundary).
struct PatchCells {
  std::vector<CellBuilder> builders;
  std::vector<const PatchData*> developablePatches;
};

PatchCells buildPatchCells(const std::vector<PatchData>& patches, double tol, int maxCellDepth) {
  PatchCells out;
  std::vector<CellBuilder>& builders = out.builders;
  for (const PatchData& data : patches) {
    if (data.developable) {
      out.developablePatches.push_back(&data);
      continue;
    }
    builders.push_back(CellBuilder{data, tol, maxCellDepth, {}, nullptr, {}});
    inPatch(data, [&] { builders.back().run(); });
    // A curved patch whose normals stay within the tolerance (its whole domain one small
    // fold cell: no regular cell, nothing to trace; K of rounding size and both signs, as
    // on a nearly flat patch) has an image below the tolerance: its boundary's normals stand
    // for it, as for a developable patch. (Beside a plane, such a patch once left the map
    // without a regular cell.)
    // Likewise a patch whose image is thinner than the tolerance everywhere (a nearly
    // developable patch: its regular cells' images all narrower than a quarter tolerance):
    // the strips of half-width tol / 2 about its boundary's images hold it.
    const std::vector<Cell>& made = builders.back().cells;
    const bool tiny = std::all_of(made.begin(), made.end(), [&](const Cell& c) {
      return c.traceAxis == 0 && (c.fold ? c.spread <= tol : c.innerRadius < 0.25 * tol);
    });
    if (tiny) {
      builders.pop_back();
      out.developablePatches.push_back(&data);
    }
  }
  return out;
}

// The pole cell: builders[builder].cells[index]; builder == builders.size() when there is
// no regular cell.
struct PoleCell {
  std::size_t builder = 0;
  std::size_t index = 0;
};

// The regular cell of largest parameter area (the first such, in patch order); the pole is
// its centre normal, inside its image, so that image is the outside of its boundary's
// projection. It is chosen before any edge is sampled because the sampling measures the
// polygon in the pole frame's plane (see NormalSampler).
PoleCell choosePoleCell(std::vector<CellBuilder>& builders, double tol) {
  std::size_t poleBuilder = builders.size(), poleIndex = 0;
  double poleArea = 0.0;
  // Without a regular cell (a patch whose normals vary little, crossed by one parabolic
  // line, is a single traced cell), the largest traced cell is split instead of traced, a
  // bounded number of times (each split quarters a cell).
  for (int split = 0; split <= 8 && poleBuilder == builders.size(); ++split) {
    std::size_t tracedBuilder = builders.size(), tracedIndex = 0;
    double tracedArea = 0.0;
    for (std::size_t b = 0; b < builders.size(); ++b) {
      const std::vector<Cell>& list = builders[b].cells;
      for (std::size_t i = 0; i < list.size(); ++i) {
        const double area = (list[i].u1 - list[i].u0) * (list[i].v1 - list[i].v0);
        if (!list[i].fold && area > poleArea) poleBuilder = b, poleIndex = i, poleArea = area;
        if (list[i].traceAxis != 0 && area > tracedArea) tracedBuilder = b, tracedIndex = i, tracedArea = area;
      }
    }
    // A cell whose image is not wide beside the tolerance cannot be the pole cell: its
    // polygon, within the tolerance of its curves, need not wind around its own centre
    // normal, and then "outside its loop" is nearly the whole plane (a nearly flat patch
    // beside a curved one made the whole map Omega, 6 of 600 random surfaces). The largest
    // regular cell whose image holds a disk of kPoleCellSpreadTolerances / 4 tolerances
    // about its centre normal (see Cell::innerRadius) wins, if there is one.
    double wideArea = 0.0;
    for (std::size_t b = 0; b < builders.size(); ++b) {
      const std::vector<Cell>& list = builders[b].cells;
      for (std::size_t i = 0; i < list.size(); ++i) {
        const double area = (list[i].u1 - list[i].u0) * (list[i].v1 - list[i].v0);
        if (!list[i].fold && list[i].innerRadius >= 0.25 * kPoleCellSpreadTolerances * tol &&
            area > wideArea) {
          poleBuilder = b, poleIndex = i, wideArea = area;
        }
      }
    }
    if (poleBuilder < builders.size() || tracedBuilder == builders.size()) break;
    CellBuilder& builder = builders[tracedBuilder];
    builder.noTrace.insert(CellBuilder::boundsOf(builder.cells[tracedIndex]));
    builder.cells.clear();
    inPatch(builder.data, [&] { builder.run(); });
  }
  return {poleBuilder, poleIndex};
}

// The pole is the cell's centre normal, or with options.offsetPole the normal at a point
// with irrational-looking offsets: a dyadic centre's normal can be exactly the normal at a
// point of another cell's (dyadic) edge on surfaces with symmetries (a surface of
// revolution repeats its normals' latitudes along every meridian). The pole on an edge's
// image puts that edge's polygon through the projection's point at infinity (the teapot's
// lower body lost its whole complement so); optimalSlicing retries with the offset pole
// when the complement comes out empty. Without a regular cell the frame's pole is
// `fallback`, a normal of the first patch.
Vec3 poleNormal(const std::vector<CellBuilder>& builders, PoleCell pole, bool offsetPole,
                const Vec3& fallback) {
  if (pole.builder == builders.size()) return fallback;
  const Cell& c = builders[pole.builder].cells[pole.index];
  const double poleOffsetU = offsetPole ? 0.4142135623730950 : 0.5;  // sqrt(2) - 1
  const double poleOffsetV = offsetPole ? 0.5811388300841898 : 0.5;  // sqrt(10)/2 - 1
  return unitNormal(*builders[pole.builder].data.patch, c.u0 + poleOffsetU * (c.u1 - c.u0),
                    c.v0 + poleOffsetV * (c.v1 - c.v0));
}

// The cell images of every curved patch, the pole cell's index among them, and counts.
struct CurvedImages {
  std::vector<CellImage> cells;
  std::size_t poleCell = 0;
  CellBuilder::ImageStats stats;
  std::size_t foldCells = 0;
};

// A patch is run again, with cells subdivided instead of traced, while some traced cell
// holds +-pole (its part would be the outside of its loop, as for the cells handled by
// insertOutside in OmegaPieces, for which only a small cell's hull can stand) or whose edges
// did not show two crossings. Regular cells come out the same, the pole cell among them.
// `pole` must outlive the builders' use (they keep its address).
CurvedImages imagesOfCurvedPatches(std::vector<CellBuilder>& builders, PoleCell poleCell,
                                   const Vec3& pole, const NormalSampler& sampler,
                                   const NormalSampler& inner) {
  CurvedImages out;
  for (std::size_t b = 0; b < builders.size(); ++b) {
    CellBuilder& builder = builders[b];
    const CellBuilder::CellBounds poleBounds =
        b == poleCell.builder ? CellBuilder::boundsOf(builder.cells[poleCell.index]) : CellBuilder::CellBounds{};
    builder.avoid = &pole;
    bool rerun = std::any_of(builder.cells.begin(), builder.cells.end(), [&](const Cell& c) {
      return c.traceAxis != 0 && builder.holdsEither(c, pole);
    });
    std::vector<CellImage> images;
    CellBuilder::ImageStats stats;
    for (int run = 0; run < 64; ++run) {
      std::vector<CellBuilder::CellBounds> untraceable;
      inPatch(builder.data, [&] {
        if (rerun) {
          builder.cells.clear();
          builder.run();
        }
        stats = {};
        images = builder.images(sampler, inner, stats, untraceable);
      });
      out.stats.untracedCells += untraceable.size();  // over every run
      if (untraceable.empty()) break;
      builder.noTrace.insert(untraceable.begin(), untraceable.end());
      rerun = true;
    }
    if (b == poleCell.builder) {
      for (std::size_t i = 0; i < builder.cells.size(); ++i) {
        if (!builder.cells[i].fold && CellBuilder::boundsOf(builder.cells[i]) == poleBounds) out.poleCell = out.cells.size() + i;
      }
    }
    out.stats.parabolicLines += stats.parabolicLines;
    out.stats.tracedCells += stats.tracedCells;
    for (const Cell& c : builder.cells) out.foldCells += c.fold && c.traceAxis == 0 ? 1 : 0;
    for (auto& c : images) out.cells.push_back(std::move(c));
  }
  return out;
}

// The images of the developable patches' boundaries: four curves per patch.
std::vector<std::vector<Vec3>> developableCurves(const std::vector<const PatchData*>& patches,
                                                 const NormalSampler& curveSampler) {
  std::vector<std::vector<Vec3>> curves;
  for (const PatchData* data : patches) {
    const BezierPatch& patch = *data->patch;
    const std::array<std::function<Vec3(double)>, 4> edges{
        [&](double s) { return unitNormal(patch, s, 0.0); },
        [&](double s) { return unitNormal(patch, 1.0, s); },
        [&](double s) { return unitNormal(patch, 1.0 - s, 1.0); },
        [&](double s) { return unitNormal(patch, 0.0, 1.0 - s); }};
    for (const auto& edge : edges) curves.push_back(curveSampler.curve(edge));
  }
  return curves;
}

// The largest angle from `first` to any sampled normal.
double spreadAbout(const Vec3& first, const std::vector<CellImage>& cells,
                   const std::vector<std::vector<Vec3>>& curves) {
  double spread = 0.0;
  for (const CellImage& c : cells) {
    for (const Vec3& n : c.normals) spread = std::max(spread, angleBetween(first, n));
  }
  for (const auto& curve : curves) {
    for (const Vec3& n : curve) spread = std::max(spread, angleBetween(first, n));
  }
  return spread;
}

// The stereographic plane of the pole frame, and Clipper's integer grid on it.
struct PlaneGrid {
  Rotation3 toPoleFrame;
  double scale = 1.0;   // grid steps per unit of the plane
  double window = 0.0;  // half-width of the square every polygon is clipped to (plane units)

  [[nodiscard]] Vec2 project(const Vec3& n) const { return stereographic(apply(toPoleFrame, n)); }

  [[nodiscard]] IntPoint toInt(const Vec2& p) const {
    return IntPoint(std::llround(p.x * scale), std::llround(p.y * scale));
  }

  // Everything outside the pole cell's loop is in Omega, so only a cell image's part inside
  // a square around that loop matters: each polygon is clipped to the square of (2 - 2^-28)
  // times the loop's extent (coordinates at most 2^30 - 2 on the grid, where Clipper's
  // products stay in 64 bits; the shrinking below only moves inward). Clipping, unlike moving far
  // vertices onto the square one by one, keeps the polygon's region and orientation: a cell
  // whose image comes close to the pole (far out in the plane) but does not hold it would
  // otherwise be folded over, and mergeSheet, which sums each sheet's cells as oriented
  // chains, would subtract it from its neighbours' region, leaving a hole in Omega.
  [[nodiscard]] IntLoop toPolygon(const std::vector<Vec2>& loop) const {
    IntLoop points;
    for (const Vec2& p : clipToSquare(loop, window)) {
      const IntPoint ip = toInt(p);
      if (points.empty() || !(points.back() == ip)) points.push_back(ip);
    }
    while (points.size() > 1 && points.front() == points.back()) points.pop_back();
    return points;
  }

  [[nodiscard]] std::vector<Vec2> toLoop(const IntLoop& contour) const {
    std::vector<Vec2> loop;
    loop.reserve(contour.size());
    for (const IntPoint& p : contour) loop.push_back({static_cast<double>(p.X) / scale, static_cast<double>(p.Y) / scale});
    return loop;
  }
};

// A simple loop (a hull, a strip, a cell's boundary) turned counter-clockwise: Omega is
// formed with the positive fill rule, every region winding +1 around its points.
IntLoop counterClockwise(IntLoop loop) {
  if (signedArea2(loop) < 0.0) std::reverse(loop.begin(), loop.end());
  return loop;
}

// One Clipper operation; its own exceptions (a coordinate out of range, which the window
// rules out) and failures become the project's.
IntLoops clip(ClipperLib::ClipType type, const IntLoops& subject, const IntLoops& clipLoops,
              ClipperLib::PolyFillType subjectFill, ClipperLib::PolyFillType clipFill) {
  IntLoops result;  // outlines counter-clockwise, holes clockwise
  bool done = false;
  try {
    ClipperLib::Clipper clipper;
    const bool anySubject = clipper.AddPaths(subject, ClipperLib::ptSubject, true);
    const bool anyClip = clipper.AddPaths(clipLoops, ClipperLib::ptClip, true);
    // No edge at all (a sheet whose cells all cancel or collapse on the grid): the result is
    // empty, and Execute would report a failure.
    if (!anySubject && !anyClip) return result;
    done = clipper.Execute(type, result, subjectFill, clipFill);
  } catch (const ClipperLib::clipperException& e) {
    throw Error(fmt::format("the Gauss map's polygon union failed: {}", e.what()));
  }
  if (!done) throw Error("the Gauss map's polygon union failed (Clipper's Execute)");
  return result;
}

// Omega's pieces in the plane, each winding +1 around its points (overlaps add up), to be
// united at the end. A piece is one or more loops (a union's outlines with their holes,
// which wind -1 and must stay with them).
class OmegaPieces {
 public:
  OmegaPieces(const PlaneGrid& grid, IntLoop outerLoop) : grid_(grid), outerLoop_(std::move(outerLoop)) {}

  // The images of the curved patches' cells, +-n, all but the pole cell's +n.
  void addCells(const std::vector<CellImage>& cells, std::size_t poleCell) {
    // Regular cells of one patch with one sign of K map with one orientation and share their
    // image vertices exactly with their neighbours (see CellBuilder): their union is the chain
    // left when every edge shared by two of them (traversed once each way) cancels. Handing
    // Clipper those few loops instead of thousands of cells makes the union cheap.
    std::map<std::tuple<const PatchData*, int, int>, IntLoops> sheets;
    // A loop of normals (for n, or -n) into its sheet. The Gauss map keeps the orientation of
    // (u, v) where K > 0 (n = r_u x r_v) and reverses it where K < 0; the antipodal map and
    // the stereographic projection from the north pole each reverse it: a part
    // (counter-clockwise in (u, v)) maps to a polygon of orientation -sign(K) for n and
    // sign(K) for -n.
    const auto addToSheet = [&](const CellImage& c, const std::vector<Vec3>& normals,
                                int curvatureSign, double sign) {
      std::vector<Vec2> loop;
      loop.reserve(normals.size());
      for (const Vec3& n : normals) loop.push_back(grid_.project(sign * n));
      sheets[{c.patch, curvatureSign, sign > 0.0 ? 1 : -1}].push_back(grid_.toPolygon(loop));
    };
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const CellImage& c = cells[i];
      for (double sign : {1.0, -1.0}) {
        if (i == poleCell && sign > 0.0) continue;
        // A cell whose image holds the pole (the Gauss map covers the pole more than once) is
        // the outside of its projected boundary: within the pole cell's loop, that loop's
        // region minus the cell loop's inside (decided in CellBuilder::images).
        const bool holdsPole = c.holdsPole[sign > 0.0 ? 0 : 1];
        if (!holdsPole && !c.fold) {
          addToSheet(c, c.normals, c.curvatureSign, sign);  // merged below
          continue;
        }
        if (!holdsPole && !c.parts.empty()) {
          for (const SheetPart& part : c.parts) addToSheet(c, part.normals, part.curvatureSign, sign);
          continue;
        }
        std::vector<Vec2> loop;
        for (const Vec3& n : c.normals) loop.push_back(grid_.project(sign * n));
        if (c.fold) loop = convexHull(std::move(loop));
        if (loop.size() < 3) continue;
        if (holdsPole) {
          insertOutside(loop);
        } else {
          // Collected only: the union is formed once, by the final difference.
          pieces_.push_back({counterClockwise(grid_.toPolygon(loop))});
        }
      }
    }
    // Each sheet joins the union as the region where its merged loops wind either way
    // (nonzero), formed on its own: the union sums windings, and one sheet's must not cancel
    // another's. Beside a parabolic line a sheet can be thinner than the tolerance: a crescent
    // between the fold's image and a patch edge's, tangent where they meet, or a spike where
    // the line runs close to a patch edge. The polygons of the two curves, each within the
    // tolerance of its curve, may then cross, and the lobes they cut off wind the wrong way.
    // Outside the tolerance of the sheet's boundary curves the polygon's winding number is
    // the curves' (the polygon is homotopic to them within that band), so the nonzero region
    // differs from the true image only within the tolerance of those curves, all of which
    // are normals: Omega's boundary stays within the tolerance, and no normal is cancelled.
    for (const auto& [unused, polygons] : sheets) {
      pieces_.push_back(clip(ClipperLib::ctUnion, mergeSheet(polygons), {}, ClipperLib::pftNonZero,
                             ClipperLib::pftNonZero));
    }
  }

  // A developable patch among curved ones: its normals form a curve (or a point) that may
  // lie outside the curved patches' region, and they are obstacles for the slicing
  // direction like any other normal, so the medial axis must see them. A curve has no
  // interior for the even-odd loops to bound: it enters Omega as strips of half-width tol / 2
  // around its polygon, sampled to tol / 2, so that Omega holds the whole curve and its
  // boundary stays within tol of it.
  void addCurves(const std::vector<std::vector<Vec3>>& curves, const Vec3& pole, double tol) {
    for (const auto& curve : curves) {
      for (double sign : {1.0, -1.0}) {
        // Each segment of the polygon (a curve has at least its two ends; a plane's are
        // equal, and its strip is a disk).
        const std::size_t segments = std::max<std::size_t>(curve.size(), 2) - 1;
        for (std::size_t i = 0; i < segments; ++i) {
          const Vec3 a = sign * curve[i];
          const Vec3 b = sign * curve[std::min(i + 1, curve.size() - 1)];
          ThinStrip strip = thinStrip(a, b, 0.5 * tol);
          // Whether the strip holds the pole, decided with a margin either side of its
          // polygon's chords (at halfWidth) and vertices (at reach): a strip passing the pole
          // in between is widened until it clearly holds it.
          const double gap = angleToArc(pole, a, b);
          if (gap > 0.45 * tol && gap <= 1.01 * strip.reach) strip = thinStrip(a, b, 2.0 * gap);
          std::vector<Vec2> loop;
          for (const Vec3& n : strip.loop) loop.push_back(grid_.project(n));
          if (gap <= 1.01 * strip.reach) {
            // The strip's image is the outside of its projected loop (as for a cell holding
            // the pole, above).
            insertOutside(loop);
          } else {
            pieces_.push_back({counterClockwise(grid_.toPolygon(loop))});
          }
        }
      }
    }
  }

  // The complement of the pieces' union within the pole cell's loop (the pieces are used up).
  IntLoops complement() {
    // Many pieces (thousands of patches: a trimmed face's pieces): one sweep over all their
    // overlapping loops makes Clipper's intersection lists grow with the square of the edges
    // a scanbeam crosses (bearing.iges's 11,336 pieces: 82 % of the time in BuildIntersectList).
    // United in groups first, a balanced tree of unions, each sweep sees a few pieces and the
    // edges inside their union vanish before the next level. The region is the same (union is
    // associative; the new vertices at crossings are rounded to the grid at each level, within
    // a grid step, as the one sweep's are); a map of a few hundred pieces keeps the one sweep.
    std::vector<IntLoops> omega = std::move(pieces_);
    while (omega.size() > kOneSweepPieces) {
      std::vector<IntLoops> united;
      for (std::size_t start = 0; start < omega.size(); start += kUnionGroup) {
        IntLoops group;
        for (std::size_t i = start; i < std::min(start + kUnionGroup, omega.size()); ++i)
          group.insert(group.end(), omega[i].begin(), omega[i].end());
        united.push_back(clip(ClipperLib::ctUnion, group, {}, ClipperLib::pftPositive, ClipperLib::pftPositive));
      }
      omega = std::move(united);
    }
    IntLoops omegaLoops;
    for (const IntLoops& piece : omega) omegaLoops.insert(omegaLoops.end(), piece.begin(), piece.end());
    return clip(ClipperLib::ctDifference, {outerLoop_}, omegaLoops, ClipperLib::pftPositive,
                ClipperLib::pftPositive);
  }

 private:
  // An image that holds the pole is the outside of its projected loop (within the window).
  void insertOutside(const std::vector<Vec2>& loop) {
    pieces_.push_back(clip(ClipperLib::ctDifference, {outerLoop_}, {counterClockwise(grid_.toPolygon(loop))},
                           ClipperLib::pftPositive, ClipperLib::pftPositive));
  }

  const PlaneGrid& grid_;
  IntLoop outerLoop_;
  std::vector<IntLoops> pieces_;
};

// The complement's loops in the plane, apart and without slivers. Parts of the complement
// may touch at a vertex (two sheets meeting at a point); the medial axis needs disjoint
// loops. Shrinking by two grid steps (2^-28 of the pole cell loop's extent; mitred corners)
// separates them and removes slivers thinner than four steps; it only grows Omega (see
// Accuracy in the contract for what it costs).
std::vector<std::vector<Vec2>> separatedLoops(const IntLoops& complement, const PlaneGrid& grid) {
  ClipperLib::PolyTree shrunk;
  try {
    ClipperLib::ClipperOffset offset;
    offset.AddPaths(complement, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
    offset.Execute(shrunk, -2.0);
  } catch (const ClipperLib::clipperException& e) {
    throw Error(fmt::format("the Gauss map's polygon union failed (shrinking): {}", e.what()));
  }

  // The parts: each outline (a node that is not a hole: top-level, or an island inside a
  // hole) with its holes. Slivers (cracks the overlaps did not close, or rounding) are tiny
  // beside the true complement: keep the parts of at least 1e-6 of the largest area.
  struct Part {
    const ClipperLib::PolyNode* outline;
    double area;  // twice the outline's area less its holes'
  };
  std::vector<Part> parts;
  std::vector<const ClipperLib::PolyNode*> pending(shrunk.Childs.begin(), shrunk.Childs.end());
  while (!pending.empty()) {
    const ClipperLib::PolyNode* node = pending.back();
    pending.pop_back();
    Part part{node, std::abs(signedArea2(node->Contour))};
    for (const ClipperLib::PolyNode* hole : node->Childs) {
      part.area -= std::abs(signedArea2(hole->Contour));
      pending.insert(pending.end(), hole->Childs.begin(), hole->Childs.end());
    }
    parts.push_back(part);
  }
  double largest = 0.0;
  for (const Part& part : parts) largest = std::max(largest, part.area);
  std::vector<std::vector<Vec2>> loops;
  for (const Part& part : parts) {
    if (part.area < 1e-6 * largest) continue;
    loops.push_back(grid.toLoop(part.outline->Contour));
    for (const ClipperLib::PolyNode* hole : part.outline->Childs) loops.push_back(grid.toLoop(hole->Contour));
  }
  return loops;
}

}  // namespace

bool isSymmetrizedNormal(const Surface& surface, const Vec3& direction) {
  std::vector<PatchData> patches;
  for (const BezierPatch& p : cornerResolved(surface).patches) patches.push_back(makePatchData(p));
  return inOmega(patches, normalized(direction));
}

GaussMap symmetrizedGaussMap(const Surface& surface, const GaussMapOptions& options) {
  validateOptions(options);
  if (surface.patches.empty()) throw Error("the surface has no patches");
  const double tol = options.toleranceRad;
  GaussMap map;
  std::vector<PatchData> patches;
  // Corners where q vanishes are blown up into fans (surface.hpp's cornerPieces): their ray
  // limits become an apex row's curve, a boundary like any other.
  std::vector<std::size_t> sources;
  const Surface resolved = cornerResolved(surface, &sources);
  for (std::size_t i = 0; i < resolved.patches.size(); ++i) {
    patches.push_back(makePatchData(resolved.patches[i]));
    patches.back().index = sources[i];
  }
  markSeams(patches);

  // At fine tolerances, a coarse map first: curves farther than a band around its boundary
  // lie deep inside Omega, and their polygons need only its tolerance (see BoundaryBand and
  // the contract). Pieces on seams are exempt: two patches' polygons of one curve, each
  // within its own tolerance, leave a sliver between them that would be a gap in Omega.
  std::optional<BoundaryBand> band;
  if (options.coarseBand && kCoarseBandFactor * tol <= kCoarseToleranceRad) {
    GaussMapOptions coarseOptions = options;
    coarseOptions.toleranceRad = kCoarseToleranceRad;
    const GaussMap coarse = symmetrizedGaussMap(surface, coarseOptions);
    if (coarse.kind == GaussMapKind::region) {
      band.emplace(coarse.sphereCurves, kBandWidthTolerances * kCoarseToleranceRad);
    }
  }

  PatchCells patchCells = buildPatchCells(patches, tol, options.maxCellDepth);
  std::vector<CellBuilder>& builders = patchCells.builders;
  const bool allDevelopable = builders.empty();

  const Vec3 first = unitNormal(surface.patches.front(), 0.5, 0.5);
  const PoleCell poleCell = choosePoleCell(builders, tol);
  map.pole = poleNormal(builders, poleCell, options.offsetPole, first);
  map.toPoleFrame = rotationTaking(map.pole, {0.0, 0.0, 1.0});

  const NormalSampler sampler{tol, map.toPoleFrame};
  NormalSampler inner = sampler;  // for curves off the seams (see BoundaryBand)
  if (band) inner.band = &*band, inner.coarseTol = kCoarseToleranceRad;
  const CurvedImages curved = imagesOfCurvedPatches(builders, poleCell, map.pole, sampler, inner);
  // Among curved patches a developable patch's curve is thickened into a strip of half-width
  // tol / 2 around a polygon sampled to tol / 2 (see OmegaPieces::addCurves): sampled to tol
  // alone, it is the image itself.
  const NormalSampler curveSampler{allDevelopable ? tol : 0.5 * tol, map.toPoleFrame};
  const std::vector<std::vector<Vec3>> curves = developableCurves(patchCells.developablePatches, curveSampler);

  // All normals within the tolerance of one direction: a plane.
  const double spread = spreadAbout(first, curved.cells, curves);
  auto asPoint = [&] {
    map.kind = GaussMapKind::point;
    map.pole = first;
    map.toPoleFrame = rotationTaking(first, {0.0, 0.0, 1.0});
    map.sphereCurves = {{first}, {-first}};
    return map;
  };
  if (spread <= tol) return asPoint();
  if (allDevelopable) {
    map.kind = GaussMapKind::curve;
    for (const auto& curve : curves) {
      map.sphereCurves.push_back(curve);
      std::vector<Vec3> opposite;
      for (const Vec3& n : curve) opposite.push_back(-n);
      map.sphereCurves.push_back(std::move(opposite));
    }
    return map;
  }
  if (poleCell.builder == builders.size()) throw Error("the Gauss map has no regular cell (K = 0 almost everywhere)");

  // The pole cell's boundary bounds everything else: scale it into the integer grid.
  PlaneGrid grid{map.toPoleFrame};
  std::vector<Vec2> outer;
  for (const Vec3& n : curved.cells[curved.poleCell].normals) outer.push_back(grid.project(n));
  double extent = 0.0;
  for (const Vec2& p : outer) extent = std::max({extent, std::abs(p.x), std::abs(p.y)});
  grid.scale = static_cast<double>(1 << 29) / extent;
  grid.window = (2.0 - 0x1p-28) * extent;
  // A map too small for the grid: the antipodal image lies about the origin, where a grid
  // step of extent / 2^29 spans two steps' angle, while the pole cell's image reaches out
  // to ~2 / (its angular radius). With the normals' spread under 32 steps (2^-24 extent) the
  // antipodal image would collapse to a few grid points (a nearly flat surface: 1 mm of twist
  // over 10 km): the map is reported as a point, like a plane's, and optimalSlicing measures
  // alpha on the surface itself.
  if (spread <= 0x1p-24 * extent) return asPoint();

  OmegaPieces omega(grid, counterClockwise(grid.toPolygon(outer)));
  omega.addCells(curved.cells, curved.poleCell);
  omega.addCurves(curves, map.pole, tol);
  map.loops = separatedLoops(omega.complement(), grid);

  const Rotation3 back = transpose(map.toPoleFrame);
  for (const auto& loop : map.loops) {
    map.boundarySegments += loop.size();
    std::vector<Vec3> onSphere;
    for (const Vec2& p : loop) onSphere.push_back(apply(back, inverseStereographic(p)));
    onSphere.push_back(onSphere.front());
    map.sphereCurves.push_back(std::move(onSphere));
  }
  map.candidatePieces = curved.cells.size();
  for (const CellImage& c : curved.cells) {
    map.imageVertices += c.normals.size();
    for (const SheetPart& part : c.parts) map.imageVertices += part.normals.size();
  }
  map.parabolicCurves = curved.stats.parabolicLines;
  map.foldCells = curved.foldCells;
  map.tracedCells = curved.stats.tracedCells;
  map.untracedCells = curved.stats.untracedCells;
  map.coarseBandUsed = band.has_value();
  return map;
}

}  // namespace scallop
