// A proof that the symmetrized Gauss map covers the sphere: caps of directions, each proven
// by the winding of a patch rectangle's boundary normals in a gnomonic chart (see
// normal_coverage.hpp for the argument and its rounding).

#include "scallop/normal_coverage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "scallop/bernstein.hpp"
#include "scallop/bezier.hpp"
#include "scallop/error.hpp"

namespace scallop {
namespace {

constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2.0;
constexpr double kSqrt3 = 1.7320508075688772;
constexpr double kHalfPi = std::numbers::pi / 2.0;
// Normals of a rectangle must stay this far (radians) inside the chart's hemisphere: the
// chart's stretch 1 / cos^2 stays below ~100.
constexpr double kChartMargin = 0.1;
// Seed cells per patch side (Newton's starting points for the preimages of a cap's centre).
constexpr int kSeedGrid = 4;
// Newton's method on the chart map: iterations, and the residual that counts as a preimage.
constexpr int kNewtonIterations = 30;
constexpr double kNewtonResidual = 1e-11;
// Edge sampling: initial uniform segments, the narrowest segment, and a per-rectangle cap
// on samples (past either: that rectangle fails, another may succeed).
constexpr int kInitialSegments = 8;
constexpr double kNarrowestSegment = 1.0 / 4096.0;
constexpr std::size_t kMaxSamplesPerCell = 4096;
// Rectangles never shrink below this half-width in parameter.
constexpr double kSmallestHalfWidth = 1.0 / (1 << 20);

double gamma(int k) {
  const double ku = k * kUnitRoundoff;
  return ku / (1.0 - ku);
}

// The normal polynomials of one patch and what the bounds need.
struct PatchData {
  const BezierPatch* patch = nullptr;
  std::array<Bernstein2, 3> n;  // N = r_u x r_v, bidegree (2m - 1, 2n - 1)
  // Bound on the rounding of one coefficient of N restricted to a rectangle (each
  // component), from bernstein.hpp's restrictTo bound, times 4.
  double coefficientError = 0.0;
};

struct Seed {
  std::size_t patch = 0;
  double u = 0.5, v = 0.5;
  Vec3 centreNormal;       // unit, or zero when |N| is not bounded below on the seed cell
  double spread = 0.0;     // normals within this angle of centreNormal (pi if unknown)
};

// A preimage of a cap's centre c: s n(u, v) = c on `patch`, with the chart Jacobian's
// smallest singular value (the local stretch of the Gauss map, per unit of parameter).
struct Preimage {
  std::size_t patch = 0;
  double sign = 1.0;
  double u = 0.0, v = 0.0;
  double stretch = 0.0;
};

struct Cap {
  int face = 0;  // cube face x, y, z = 1
  double a0 = -1.0, a1 = 1.0, b0 = -1.0, b1 = 1.0;
  int depth = 0;
  std::vector<Preimage> parentPreimages;
};

Vec3 faceDirection(int face, double a, double b) {
  switch (face) {
    case 0: return {1.0, a, b};
    case 1: return {a, 1.0, b};
    default: return {a, b, 1.0};
  }
}

double angleBetween(const Vec3& p, const Vec3& q) {
  return std::atan2(norm(cross(p, q)), dot(p, q));
}

// An orthonormal pair (e1, e2) completing the unit c to a right-handed frame.
std::pair<Vec3, Vec3> frameAbout(const Vec3& c) {
  const Vec3 axis = std::abs(c.x) <= std::abs(c.y) && std::abs(c.x) <= std::abs(c.z)
                        ? Vec3{1.0, 0.0, 0.0}
                        : (std::abs(c.y) <= std::abs(c.z) ? Vec3{0.0, 1.0, 0.0}
                                                          : Vec3{0.0, 0.0, 1.0});
  const Vec3 e1 = normalized(cross(c, axis));
  return {e1, cross(c, e1)};
}

Vec3 evaluateVector(const std::array<Bernstein2, 3>& p, double u, double v) {
  return {evaluate(p[0], u, v), evaluate(p[1], u, v), evaluate(p[2], u, v)};
}

// De Casteljau on vector coefficients (error per component <= gamma_{3q} max |c_i|).
Vec3 deCasteljau(const std::vector<Vec3>& c, double t) {
  std::array<Vec3, 64> b{};
  const std::size_t n = c.size();
  std::copy(c.begin(), c.end(), b.begin());
  const double s = 1.0 - t;
  for (std::size_t r = 1; r < n; ++r) {
    for (std::size_t i = 0; i + r < n; ++i) b[i] = s * b[i] + t * b[i + 1];
  }
  return b[0];
}

enum class CellResult { proven, failed, skipped };

class Prover {
 public:
  Prover(const Surface& surface, const NormalCoverageOptions& options) : options_(options) {
    for (const BezierPatch& patch : surface.patches) {
      PatchData data;
      data.patch = &patch;
      data.n = normalPolynomials(patch);
      double largest = 0.0;
      for (int k = 0; k < 3; ++k) {
        for (double c : data.n[k].coefficients) largest = std::max(largest, std::abs(c));
      }
      data.coefficientError =
          4.0 * (gamma(6 * data.n[0].degreeU) + gamma(6 * data.n[0].degreeV) + gamma(4)) *
          largest;
      patches_.push_back(std::move(data));
    }
    for (std::size_t p = 0; p < patches_.size(); ++p) {
      for (int i = 0; i < kSeedGrid; ++i) {
        for (int j = 0; j < kSeedGrid; ++j) {
          const double u0 = double(i) / kSeedGrid, u1 = double(i + 1) / kSeedGrid;
          const double v0 = double(j) / kSeedGrid, v1 = double(j + 1) / kSeedGrid;
          Seed seed;
          seed.patch = p;
          seed.u = 0.5 * (u0 + u1);
          seed.v = 0.5 * (v0 + v1);
          seed.spread = std::numbers::pi;
          std::array<Bernstein2, 3> r;
          for (int k = 0; k < 3; ++k) r[k] = restrictTo(patches_[p].n[k], u0, u1, v0, v1);
          const Vec3 centre = evaluateVector(r, 0.5, 0.5);
          if (norm(centre) > 0.0) {
            seed.centreNormal = normalized(centre);
            double lower = 0.0, perpendicular = 0.0;
            coneBounds(r, seed.centreNormal, patches_[p].coefficientError, lower, perpendicular);
            if (lower > 0.0) seed.spread = spreadOf(lower, perpendicular);
          }
          seeds_.push_back(seed);
        }
      }
    }
  }

  NormalCoverage run() {
    NormalCoverage result;
    std::vector<Cap> stack;
    for (int face = 2; face >= 0; --face) stack.push_back(Cap{face, -1.0, 1.0, -1.0, 1.0, 0, {}});
    while (!stack.empty()) {
      Cap cap = std::move(stack.back());
      stack.pop_back();
      if (result.caps >= options_.maxCaps || cells_ >= options_.maxCells) {
        return finish(result, CoverageOutcome::budget, cap);
      }
      ++result.caps;
      result.deepestCap = std::max(result.deepestCap, cap.depth);
      const double am = 0.5 * (cap.a0 + cap.a1), bm = 0.5 * (cap.b0 + cap.b1);
      const Vec3 c = normalized(faceDirection(cap.face, am, bm));
      double radius = 0.0;
      for (double a : {cap.a0, cap.a1}) {
        for (double b : {cap.b0, cap.b1}) {
          radius = std::max(radius, angleBetween(c, normalized(faceDirection(cap.face, a, b))));
        }
      }
      // Rounded up: the corners' directions and the angle carry a few ulps.
      radius = radius * (1.0 + 1e-12) + 1e-15;
      std::vector<Preimage> preimages;
      bool proven = false;
      // A rectangle's normals spread at most maxCellSpreadRad: a wider cap cannot fit.
      if (radius < options_.maxCellSpreadRad) {
        // First the parent's preimages, followed by Newton (cheap, and usually enough);
        // then the seed cells too, for preimages that appeared across a fold's image.
        preimages = findPreimages(c, cap.parentPreimages, false);
        proven = proveCap(c, radius, preimages, {});
        if (!proven) {
          std::vector<Preimage> all = findPreimages(c, preimages, true);
          proven = proveCap(c, radius, all, preimages);
          preimages = std::move(all);
        }
      }
      if (proven) {
        ++result.provenCaps;
        result.smallestCapRad = result.smallestCapRad == 0.0
                                    ? radius
                                    : std::min(result.smallestCapRad, radius);
        continue;
      }
      if (cap.depth >= options_.maxCapDepth) {
        return finish(result,
                      preimages.empty() ? CoverageOutcome::noPreimage : CoverageOutcome::capDepth,
                      cap);
      }
      // Children in reverse order on the stack, so the first quadrant is examined first.
      for (int q = 3; q >= 0; --q) {
        Cap child;
        child.face = cap.face;
        child.depth = cap.depth + 1;
        child.a0 = (q & 1) != 0 ? am : cap.a0;
        child.a1 = (q & 1) != 0 ? cap.a1 : am;
        child.b0 = (q & 2) != 0 ? bm : cap.b0;
        child.b1 = (q & 2) != 0 ? cap.b1 : bm;
        child.parentPreimages = preimages;
        stack.push_back(std::move(child));
      }
    }
    result.proven = true;
    result.outcome = CoverageOutcome::proven;
    collect(result);
    return result;
  }

 private:
  NormalCoverage& finish(NormalCoverage& result, CoverageOutcome outcome, const Cap& cap) {
    result.proven = false;
    result.outcome = outcome;
    const double am = 0.5 * (cap.a0 + cap.a1), bm = 0.5 * (cap.b0 + cap.b1);
    result.unprovenDirection = normalized(faceDirection(cap.face, am, bm));
    double radius = 0.0;
    for (double a : {cap.a0, cap.a1}) {
      for (double b : {cap.b0, cap.b1}) {
        radius = std::max(radius, angleBetween(result.unprovenDirection,
                                               normalized(faceDirection(cap.face, a, b))));
      }
    }
    result.unprovenCapRad = radius;
    collect(result);
    return result;
  }

  void collect(NormalCoverage& result) const {
    result.cells = cells_;
    result.skippedCells = skipped_;
    result.samples = samples_;
  }

  // Over the rectangle whose restricted N is r: lower <= min d . N (<= |N|) and
  // perpendicular >= max |N - (d . N) d|, from the Bernstein coefficients (convex hull: both
  // are a linear map of N), less / plus their rounding. Every normal then lies within
  // atan(perpendicular / lower) of d when lower > 0.
  static void coneBounds(const std::array<Bernstein2, 3>& r, const Vec3& d,
                         double coefficientError, double& lower, double& perpendicular) {
    lower = std::numeric_limits<double>::infinity();
    perpendicular = 0.0;
    double largest = 0.0;
    const std::size_t count = r[0].coefficients.size();
    for (std::size_t i = 0; i < count; ++i) {
      const Vec3 c{r[0].coefficients[i], r[1].coefficients[i], r[2].coefficients[i]};
      const double along = dot(d, c);
      lower = std::min(lower, along);
      perpendicular = std::max(perpendicular, norm(c - along * d));
      largest = std::max(largest, norm(c));
    }
    // d . c and c - (d . c) d round by a few ulps of |c| (|d| = 1 up to an ulp); the
    // coefficients by coefficientError per component, sqrt(3) of it in length.
    const double rounding = kSqrt3 * coefficientError + 8.0 * kUnitRoundoff * largest;
    lower -= rounding;
    perpendicular += 2.0 * rounding;
  }

  static double spreadOf(double lower, double perpendicular) {
    return std::atan2(perpendicular, lower) * (1.0 + 1e-12) + 1e-15;
  }

  // The chart map g(u, v) = (N . e1, N . e2) / (N . s c) and its Jacobian; false outside
  // the chart's useful part (N . s c small).
  struct ChartValue {
    double ga = 0.0, gb = 0.0, j11 = 0.0, j12 = 0.0, j21 = 0.0, j22 = 0.0;
    double residual() const { return std::hypot(ga, gb); }
  };
  static bool chartAt(const PatchData& data, const Vec3& sc, const Vec3& e1, const Vec3& e2,
                      double u, double v, ChartValue& out) {
    // N = r_u x r_v, N_u = r_uu x r_v + r_u x r_uv, N_v = r_uv x r_v + r_u x r_vv: one pass
    // over the control net (the Bernstein forms of N cost several times more).
    const PatchDerivatives r = derivativesToSecondOrder(*data.patch, u, v);
    const Vec3 n = cross(r.u, r.v);
    const double w = dot(n, sc);
    if (!(w > 1e-3 * norm(n))) return false;
    const Vec3 nu = cross(r.uu, r.v) + cross(r.u, r.uv);
    const Vec3 nv = cross(r.uv, r.v) + cross(r.u, r.vv);
    out.ga = dot(n, e1) / w;
    out.gb = dot(n, e2) / w;
    const double wu = dot(nu, sc), wv = dot(nv, sc);
    out.j11 = (dot(nu, e1) - out.ga * wu) / w;
    out.j12 = (dot(nv, e1) - out.ga * wv) / w;
    out.j21 = (dot(nu, e2) - out.gb * wu) / w;
    out.j22 = (dot(nv, e2) - out.gb * wv) / w;
    return true;
  }

  // Newton's method with backtracking on g(u, v) = 0 from (u, v), kept in [0, 1]^2.
  static bool newton(const PatchData& data, double sign, const Vec3& c, const Vec3& e1,
                     const Vec3& e2, double& u, double& v, double& stretch) {
    const Vec3 sc = sign * c;
    ChartValue g;
    if (!chartAt(data, sc, e1, e2, u, v, g)) return false;
    for (int it = 0; it < kNewtonIterations; ++it) {
      if (g.residual() < kNewtonResidual) {
        // Smallest singular value of the 2 x 2 Jacobian.
        const double f = g.j11 * g.j11 + g.j12 * g.j12 + g.j21 * g.j21 + g.j22 * g.j22;
        const double det = std::abs(g.j11 * g.j22 - g.j12 * g.j21);
        const double disc = std::sqrt(std::max(0.0, f * f - 4.0 * det * det));
        stretch = std::sqrt(std::max(0.0, 0.5 * (f - disc)));
        return true;
      }
      const double det = g.j11 * g.j22 - g.j12 * g.j21;
      if (!(std::abs(det) > 0.0) || !std::isfinite(det)) return false;
      double du = -(g.j22 * g.ga - g.j12 * g.gb) / det;
      double dv = -(-g.j21 * g.ga + g.j11 * g.gb) / det;
      const double step = std::hypot(du, dv);
      if (step > 0.25) du *= 0.25 / step, dv *= 0.25 / step;
      bool moved = false;
      for (int halving = 0; halving < 12 && !moved; ++halving) {
        const double un = std::clamp(u + du, 0.0, 1.0), vn = std::clamp(v + dv, 0.0, 1.0);
        ChartValue next;
        if (chartAt(data, sc, e1, e2, un, vn, next) && next.residual() < g.residual()) {
          u = un;
          v = vn;
          g = next;
          moved = true;
        }
        du *= 0.5;
        dv *= 0.5;
      }
      if (!moved) return false;  // a local minimum of |g| that is no root, or stuck on an edge
    }
    return false;
  }

  static bool samePreimage(const Preimage& p, std::size_t patch, double sign, double u,
                           double v) {
    return p.patch == patch && p.sign == sign && std::abs(p.u - u) < 1e-7 &&
           std::abs(p.v - v) < 1e-7;
  }

  // Preimages of c by Newton's method from the hints and, if useSeeds, from the seed cells
  // whose normal cone (widened by 0.05 rad) holds +-c; distinct, steepest first.
  std::vector<Preimage> findPreimages(const Vec3& c, const std::vector<Preimage>& hints,
                                      bool useSeeds) {
    const auto [e1, e2] = frameAbout(c);
    std::vector<Preimage> found;
    auto tryFrom = [&](std::size_t patch, double sign, double u, double v) {
      double stretch = 0.0;
      if (!newton(patches_[patch], sign, c, e1, e2, u, v, stretch)) return;
      for (const Preimage& p : found) {
        if (samePreimage(p, patch, sign, u, v)) return;
      }
      found.push_back(Preimage{patch, sign, u, v, stretch});
    };
    for (const Preimage& h : hints) tryFrom(h.patch, h.sign, h.u, h.v);
    for (const Seed& seed : seeds_) {
      if (!useSeeds) break;
      for (double sign : {1.0, -1.0}) {
        const bool inCone = seed.spread >= std::numbers::pi ||
                            angleBetween(sign * c, seed.centreNormal) <= seed.spread + 0.05;
        if (!inCone) continue;
        // A preimage already inside this seed cell makes Newton from it redundant.
        const double half = 0.5 / kSeedGrid;
        const bool known = std::any_of(found.begin(), found.end(), [&](const Preimage& p) {
          return p.patch == seed.patch && p.sign == sign && std::abs(p.u - seed.u) <= half &&
                 std::abs(p.v - seed.v) <= half;
        });
        if (!known) tryFrom(seed.patch, sign, seed.u, seed.v);
      }
    }
    // The steepest preimages first: their rectangles hold a cap at the smallest size.
    std::stable_sort(found.begin(), found.end(),
                     [](const Preimage& p, const Preimage& q) { return p.stretch > q.stretch; });
    return found;
  }

  // Tries rectangles about each preimage not in `tried`.
  bool proveCap(const Vec3& c, double radius, const std::vector<Preimage>& preimages,
                const std::vector<Preimage>& tried) {
    const double tanR = std::tan(radius) * (1.0 + 4.0 * kUnitRoundoff);
    const auto [e1, e2] = frameAbout(c);
    for (const Preimage& p : preimages) {
      const bool seen = std::any_of(tried.begin(), tried.end(), [&](const Preimage& q) {
        return samePreimage(q, p.patch, p.sign, p.u, p.v);
      });
      if (seen) continue;
      double previous = -1.0;
      for (double factor : {2.0, 4.0, 8.0}) {
        if (cells_ >= options_.maxCells) return false;
        const double h = std::clamp(p.stretch > 0.0 ? factor * tanR / p.stretch : 0.5,
                                    kSmallestHalfWidth, 0.5);
        if (h == previous) continue;
        previous = h;
        auto window = [h](double t) {
          const double lo = std::clamp(t - h, 0.0, 1.0 - 2.0 * h);
          return std::pair<double, double>{lo, h >= 0.5 ? 1.0 : lo + 2.0 * h};
        };
        const auto [u0, u1] = window(p.u);
        const auto [v0, v1] = window(p.v);
        const CellResult r = testCell(p.patch, p.sign, u0, u1, v0, v1, c, e1, e2, tanR);
        if (r == CellResult::proven) return true;
      }
    }
    return false;
  }

  // The winding test of the rectangle [u0, u1] x [v0, v1] of `patch` for the cap of centre c
  // and chart radius tanR, with normals s n (see the header's steps 1 to 4).
  CellResult testCell(std::size_t patch, double sign, double u0, double u1, double v0, double v1,
                      const Vec3& c, const Vec3& e1, const Vec3& e2, double tanR) {
    ++cells_;
    const PatchData& data = patches_[patch];
    std::array<Bernstein2, 3> r;
    for (int k = 0; k < 3; ++k) r[k] = restrictTo(data.n[k], u0, u1, v0, v1);
    const Vec3 centre = evaluateVector(r, 0.5, 0.5);
    if (!(norm(centre) > 0.0)) return ++skipped_, CellResult::skipped;
    const Vec3 d = normalized(centre);
    double lower = 0.0, perpendicular = 0.0;
    coneBounds(r, d, data.coefficientError, lower, perpendicular);
    if (!(lower > 0.0)) return ++skipped_, CellResult::skipped;
    // Step 1: the normals lie within rho of d, and s n . c >= cmin > 0.
    const double rho = spreadOf(lower, perpendicular);
    if (rho > options_.maxCellSpreadRad) return CellResult::failed;
    const double offset = angleBetween(sign * d, c) + 1e-12;
    if (offset + rho > kHalfPi - kChartMargin) return CellResult::failed;
    const double cmin = std::cos(offset + rho) * (1.0 - 1e-12);
    const double stretch = 1.0 / (cmin * cmin);
    // Step 2 and 3 along the four edges, counter-clockwise in (u, v); each edge's Bernstein
    // coefficients are the boundary row or column of r (reversed: the parameter runs back),
    // so consecutive edges share their corner coefficient exactly.
    const int m = r[0].degreeU, n = r[0].degreeV;
    auto coefficient = [&](int i, int j) {
      const std::size_t at = static_cast<std::size_t>(i * (n + 1) + j);
      return Vec3{r[0].coefficients[at], r[1].coefficients[at], r[2].coefficients[at]};
    };
    std::vector<Vec2> polygon;
    std::vector<Vec3> edge;
    std::vector<std::pair<double, Vec2>> pending;
    for (int side = 0; side < 4; ++side) {
      edge.clear();
      if (side == 0) {
        for (int i = 0; i <= m; ++i) edge.push_back(coefficient(i, 0));
      } else if (side == 1) {
        for (int j = 0; j <= n; ++j) edge.push_back(coefficient(m, j));
      } else if (side == 2) {
        for (int i = m; i >= 0; --i) edge.push_back(coefficient(i, n));
      } else {
        for (int j = n; j >= 0; --j) edge.push_back(coefficient(0, j));
      }
      const int q = static_cast<int>(edge.size()) - 1;
      if (q + 1 > 64) return CellResult::failed;
      double edgeLower = std::numeric_limits<double>::infinity(), largest = 0.0, slope = 0.0;
      for (int i = 0; i <= q; ++i) {
        edgeLower = std::min(edgeLower, dot(d, edge[i]));
        largest = std::max({largest, std::abs(edge[i].x), std::abs(edge[i].y),
                            std::abs(edge[i].z)});
        if (i < q) slope = std::max(slope, norm(edge[i + 1] - edge[i]));
      }
      edgeLower -= kSqrt3 * data.coefficientError + 4.0 * kUnitRoundoff * norm(edge[0]) +
                   4.0 * kUnitRoundoff * largest * kSqrt3;
      if (!(edgeLower > 0.0)) return ++skipped_, CellResult::skipped;
      // |dN/dt| <= q max |c_{i+1} - c_i| (the derivative's coefficients), rounding added.
      const double derivative =
          q * (slope * (1.0 + 4.0 * kUnitRoundoff) + 2.0 * kSqrt3 * data.coefficientError);
      const double lipschitz = derivative / edgeLower * stretch * (1.0 + 1e-12);
      // A sample's chart point is off by at most eps: N by gamma_{3q} of its largest
      // coefficient plus the coefficients' rounding, the direction by twice that over |N|,
      // the chart by its stretch, and the chart's own arithmetic.
      const double eps =
          4.0 * (2.0 * kSqrt3 * (gamma(3 * q + 4) * largest + data.coefficientError) /
                     edgeLower * stretch +
                 16.0 * kUnitRoundoff * stretch);
      if (!(tanR > 4.0 * eps)) return CellResult::failed;
      auto chart = [&](double t) {
        ++samples_;
        const Vec3 x = deCasteljau(edge, t);
        const double w = dot(x, c);
        return Vec2{dot(x, e1) / w, dot(x, e2) / w};
      };
      double ta = 0.0;
      Vec2 pa = chart(0.0);
      if (side == 0) polygon.push_back(pa);
      pending.clear();
      for (int k = kInitialSegments; k >= 1; --k) {
        const double t = double(k) / kInitialSegments;
        pending.emplace_back(t, chart(t));
      }
      std::size_t cellSamples = 0;
      while (!pending.empty()) {
        const auto [tb, pb] = pending.back();
        if (!(norm(pa) > tanR + 2.0 * eps)) return CellResult::failed;  // inside the cap
        if (norm(pa) + norm(pb) - 2.0 * tanR - 2.0 * eps > lipschitz * (tb - ta)) {
          polygon.push_back(pb);
          ta = tb;
          pa = pb;
          pending.pop_back();
          continue;
        }
        if (tb - ta < kNarrowestSegment || ++cellSamples > kMaxSamplesPerCell) {
          return CellResult::failed;
        }
        const double tm = 0.5 * (ta + tb);
        pending.emplace_back(tm, chart(tm));
      }
    }
    // Step 4: the winding number of the closed polygon about 0 (its last vertex is the
    // first: the corner coefficient is shared). No segment comes within tanR of 0, so each
    // turn is below pi and the sum is an integer multiple of 2 pi to rounding.
    double turn = 0.0;
    for (std::size_t i = 0; i + 1 < polygon.size(); ++i) {
      turn += std::atan2(cross(polygon[i], polygon[i + 1]), dot(polygon[i], polygon[i + 1]));
    }
    const double winding = turn / (2.0 * std::numbers::pi);
    const double rounded = std::round(winding);
    if (std::abs(winding - rounded) > 0.25) return CellResult::failed;  // cannot happen
    return rounded != 0.0 ? CellResult::proven : CellResult::failed;
  }

  NormalCoverageOptions options_;
  std::vector<PatchData> patches_;
  std::vector<Seed> seeds_;
  std::size_t cells_ = 0;
  std::size_t skipped_ = 0;
  std::size_t samples_ = 0;
};

}  // namespace

NormalCoverage proveNormalsCoverSphere(const Surface& surface,
                                       const NormalCoverageOptions& options) {
  if (surface.patches.empty()) throw Error("proveNormalsCoverSphere: the surface has no patches");
  if (!(options.maxCellSpreadRad > 0.0 && options.maxCellSpreadRad <= 1.0)) {
    throw Error("proveNormalsCoverSphere: maxCellSpreadRad must lie in (0, 1]");
  }
  if (options.maxCapDepth < 0 || options.maxCapDepth > 30) {
    throw Error("proveNormalsCoverSphere: maxCapDepth must lie in 0 .. 30");
  }
  if (options.maxCaps < 1 || options.maxCells < 1) {
    throw Error("proveNormalsCoverSphere: the budgets must be at least 1");
  }
  for (std::size_t i = 0; i < surface.patches.size(); ++i) {
    const BezierPatch& p = surface.patches[i];
    if (p.degreeU > kMaxPatchDegree || p.degreeV > kMaxPatchDegree) {
      throw Error("proveNormalsCoverSphere: patches[" + std::to_string(i) +
                  "]: degree above kMaxPatchDegree");
    }
    for (const Vec3& q : p.control) {
      if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z)) {
        throw Error("proveNormalsCoverSphere: patches[" + std::to_string(i) +
                    "]: control points must be finite");
      }
    }
  }
  return Prover(surface, options).run();
}

}  // namespace scallop
