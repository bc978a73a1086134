// A proof that the symmetrized Gauss map covers the sphere: caps of directions, each proven
// by the winding of a patch rectangle's boundary normals in a gnomonic chart (see
// normal_coverage.hpp for the argument and its rounding).

#include "scallop/slicing/normal_coverage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/tolerances.hpp"

namespace scallop {
namespace {

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

// The normal direction polynomials of one patch and what the bounds need.
struct PatchData {
  const BezierPatch* patch = nullptr;
  // q: N = r_u x r_v with collapsed edges' factors divided out (normalDirectionPolynomials),
  // bidegree at most (2m - 1, 2n - 1); q = N on a patch without collapsed edges.
  std::array<Bernstein2, 3> n;
  // dq/du, dq/dv, for Newton on patches with collapsed edges (N vanishes on the apex row).
  std::array<Bernstein2, 3> nu, nv;
  bool divided = false;
  // Bound on the rounding of one coefficient of q restricted to a rectangle (each
  // component), from bernstein.hpp's restrictTo bound, plus the division's, times 4.
  double coefficientError = 0.0;
  // Per patch edge (0: v = 0, 1: u = 1, 2: v = 1, 3: u = 0): the edge's control points all
  // equal (an apex row), and q's coefficients on it all parallel (its normal is constant).
  std::array<bool, 4> collapsed{};
  std::array<bool, 4> constantEdge{};
  // q's Bernstein coefficients along each patch edge (edgeRow), for the fold screen.
  std::array<std::vector<Vec3>, 4> rows;
};

// A patch edge glued to another (or to another edge of the same patch): q along the two
// edges, the second's parameter reversed or not, is parallel (certified), so the unit normals
// agree up to sign along them.
struct Glue {
  std::size_t patch = 0;
  int edge = 0;
  bool reversed = false;
  bool shared = false;  // the edges' control points are equal bit for bit
};

// A rectangle of an assembly: orientation +-1, and the sides that are glued to another
// rectangle of the assembly (cancelled in the boundary chain).
struct Rect {
  std::size_t patch = 0;
  double u0 = 0.0, u1 = 1.0, v0 = 0.0, v1 = 1.0;
  double orientation = 1.0;
  std::array<bool, 4> glued{};
  // Whether sides of constant normal (certified on the rectangle's own coefficients) are
  // dropped from the boundary: set for the strips along fold lines (proveAcrossFold).
  bool constantSides = false;
  bool same(const Rect& r) const {
    return patch == r.patch && u0 == r.u0 && u1 == r.u1 && v0 == r.v0 && v1 == r.v1;
  }
};

// Rectangle bounds are multiples of this (exact, and 1 - x is exact): glued sides match
// exactly in parameter.
constexpr double kGrid = 1.0 / (1 << 20);
// Largest rectangles in an assembly (a cycle around a vertex has 4 on the teapot).
constexpr std::size_t kMaxAssembly = 8;
// Fold lines of constant normal are looked for at multiples of 2^-kFoldLevels.
constexpr int kFoldLevels = 10;

// The coefficients of q on patch edge `edge`, its parameter increasing.
std::vector<Vec3> edgeRow(const std::array<Bernstein2, 3>& r, int edge) {
  const int m = r[0].degreeU, n = r[0].degreeV;
  auto at = [&](int i, int j) {
    const std::size_t k = static_cast<std::size_t>(i * (n + 1) + j);
    return Vec3{r[0].coefficients[k], r[1].coefficients[k], r[2].coefficients[k]};
  };
  std::vector<Vec3> row;
  if (edge == 0 || edge == 2) {
    for (int i = 0; i <= m; ++i) row.push_back(at(i, edge == 0 ? 0 : n));
  } else {
    for (int j = 0; j <= n; ++j) row.push_back(at(edge == 3 ? 0 : m, j));
  }
  return row;
}

// The control points of patch edge `edge`, its parameter increasing.
std::vector<Vec3> edgeControl(const BezierPatch& p, int edge) {
  std::vector<Vec3> row;
  if (edge == 0 || edge == 2) {
    for (int i = 0; i <= p.degreeU; ++i) row.push_back(p.at(i, edge == 0 ? 0 : p.degreeV));
  } else {
    for (int j = 0; j <= p.degreeV; ++j) row.push_back(p.at(edge == 3 ? 0 : p.degreeU, j));
  }
  return row;
}

double binomial(int n, int k) {
  double b = 1.0;
  for (int i = 1; i <= k; ++i) b = b * (n - k + i) / i;
  return b;
}

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
  double largestStretch = 0.0;  // the Jacobian's largest singular value
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

// The same from the basis values, shared by the three components: O(mn) per component
// where de Casteljau takes O(mn(m + n)). For Newton's steps only (a heuristic: its
// rounding is not part of any bound); degrees below 64.
Vec3 evaluateVectorFast(const std::array<Bernstein2, 3>& p, double u, double v) {
  const int m = p[0].degreeU, n = p[0].degreeV;
  std::array<double, 64> bu{}, bv{};
  auto basis = [](int d, double t, std::array<double, 64>& b) {
    b[0] = 1.0;
    for (int r = 1; r <= d; ++r) {  // b_i^r = (1 - t) b_i^(r-1) + t b_(i-1)^(r-1)
      b[static_cast<std::size_t>(r)] = t * b[static_cast<std::size_t>(r - 1)];
      for (int i = r - 1; i >= 1; --i) {
        b[static_cast<std::size_t>(i)] =
            (1.0 - t) * b[static_cast<std::size_t>(i)] + t * b[static_cast<std::size_t>(i - 1)];
      }
      b[0] *= 1.0 - t;
    }
  };
  basis(m, u, bu);
  basis(n, v, bv);
  std::array<double, 3> out{};
  for (std::size_t c = 0; c < 3; ++c) {
    const std::vector<double>& coefficients = p[c].coefficients;
    for (int i = 0; i <= m; ++i) {
      double row = 0.0;
      const std::size_t offset = static_cast<std::size_t>(i) * static_cast<std::size_t>(n + 1);
      for (int j = 0; j <= n; ++j) row += coefficients[offset + static_cast<std::size_t>(j)] * bv[static_cast<std::size_t>(j)];
      out[c] += row * bu[static_cast<std::size_t>(i)];
    }
  }
  return {out[0], out[1], out[2]};
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
      const std::array<Bernstein2, 3> full = normalPolynomials(patch);
      const NormalDirection direction = normalDirectionPolynomials(patch);
      data.n = direction.polynomials;
      data.divided = direction.powers.any();
      double largestN = 0.0, largestQ = 0.0;
      for (int k = 0; k < 3; ++k) {
        for (double c : full[k].coefficients) largestN = std::max(largestN, std::abs(c));
        for (double c : data.n[k].coefficients) largestQ = std::max(largestQ, std::abs(c));
      }
      // N's coefficients (products of differences) round by gamma_4 of their size; each
      // division by an edge factor scales the kept coefficients by up to the degree, rounds
      // once, and drops a row below unitNormal's threshold (bernstein.hpp, bezier.hpp).
      const int divisions = direction.powers.u0 + direction.powers.u1 + direction.powers.v0 +
                            direction.powers.v1;
      double amplification = 1.0;
      for (int k = 0; k < divisions; ++k) {
        amplification *= std::max(full[0].degreeU, full[0].degreeV);
      }
      const double divisionError =
          divisions == 0 ? 0.0
                         : amplification * (gamma(4 + divisions) * largestN +
                                            normalRoundingThreshold(patch));
      data.coefficientError =
          4.0 * ((gamma(6 * data.n[0].degreeU) + gamma(6 * data.n[0].degreeV) + gamma(4)) *
                     std::max(largestQ, largestN) +
                 divisionError);
      if (data.divided) {
        for (int k = 0; k < 3; ++k) {
          data.nu[k] = derivativeU(data.n[k]);
          data.nv[k] = derivativeV(data.n[k]);
        }
      }
      for (int edge = 0; edge < 4; ++edge) {
        data.rows[edge] = edgeRow(data.n, edge);
        const std::vector<Vec3> points = edgeControl(patch, edge);
        data.collapsed[edge] = std::all_of(points.begin(), points.end(),
                                           [&](const Vec3& p) { return p == points[0]; });
        if (!data.collapsed[edge]) continue;
        // Constant normal along the apex row: every coefficient of q there parallel to the
        // first (to within their rounding), so q(t) = lambda(t) a_0 on the edge.
        data.constantEdge[edge] = constantRow(data.rows[edge], data.coefficientError);
      }
      patches_.push_back(std::move(data));
    }
    buildGlues();
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
    result.gluedCaps = glued_;
  }

  // True when the polynomial with Bernstein coefficients `row` (each component within
  // `coefficientError` of the true one) has a constant direction: every true coefficient is
  // parallel to the first (|a_j x a_0| within the bound of the computed ones' errors through
  // the product and its rounding) and on its side (a_j . a_0 > 0), as for an apex row; so
  // q(t) = lambda(t) a_0 with lambda > 0 and the unit normal is a_0 / |a_0| along it.
  static bool constantRow(const std::vector<Vec3>& row, double coefficientError) {
    if (!(norm(row[0]) > 0.0)) return false;
    for (const Vec3& a : row) {
      const double tolerance = 2.0 * kSqrt3 * coefficientError * (norm(a) + norm(row[0])) +
                               gamma(8) * norm(a) * norm(row[0]);
      if (!(norm(cross(a, row[0])) <= tolerance && dot(a, row[0]) > 0.0)) return false;
    }
    return true;
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
    // On a patch with collapsed edges q and its derivatives come from the Bernstein forms
    // (N vanishes on the apex row; g is the same for q, N's positive multiple, inside).
    Vec3 n, nu, nv;
    if (data.divided) {
      n = evaluateVectorFast(data.n, u, v);
      nu = evaluateVectorFast(data.nu, u, v);
      nv = evaluateVectorFast(data.nv, u, v);
    } else {
      const PatchDerivatives r = derivativesToSecondOrder(*data.patch, u, v);
      n = cross(r.u, r.v);
      nu = cross(r.uu, r.v) + cross(r.u, r.uv);
      nv = cross(r.uv, r.v) + cross(r.u, r.vv);
    }
    const double w = dot(n, sc);
    if (!(w > 1e-3 * norm(n))) return false;
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
                     const Vec3& e2, double& u, double& v, double& stretch,
                     double& largestStretch) {
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
        largestStretch = std::sqrt(std::max(0.0, 0.5 * (f + disc)));
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
    // Named, not a structured binding: the lambda below captures them (clang 14, which the
    // fuzz build uses, cannot capture structured bindings).
    const auto frame = frameAbout(c);
    const Vec3 e1 = frame.first, e2 = frame.second;
    std::vector<Preimage> found;
    auto tryFrom = [&](std::size_t patch, double sign, double u, double v) {
      double stretch = 0.0, largest = 0.0;
      if (!newton(patches_[patch], sign, c, e1, e2, u, v, stretch, largest)) return;
      for (const Preimage& p : found) {
        if (samePreimage(p, patch, sign, u, v)) return;
      }
      found.push_back(Preimage{patch, sign, u, v, stretch, largest});
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

  // Tries rectangles about each preimage not in `tried`: at each size, the assembly the
  // rectangle grows into across glued edges (assemble), then the rectangle alone.
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
        const double h = dyadicFloor(std::clamp(
            p.stretch > 0.0 ? factor * tanR / p.stretch : 0.5, kSmallestHalfWidth, 0.5));
        if (h == previous) continue;
        previous = h;
        auto window = [h](double t) {
          if (h >= 0.5) return std::pair<double, double>{0.0, 1.0};
          const double lo = std::floor(std::clamp(t - h, 0.0, 1.0 - 2.0 * h) / kGrid) * kGrid;
          return std::pair<double, double>{lo, lo + 2.0 * h};
        };
        Rect r;
        r.patch = p.patch;
        std::tie(r.u0, r.u1) = window(p.u);
        std::tie(r.v0, r.v1) = window(p.v);
        // Along a collapsed edge of constant normal (an apex row), a strip the whole edge
        // long, as deep as the Gauss map's steepest stretch asks (the apex's preimage is the
        // whole row, so the smallest stretch says nothing there).
        const PatchData& data = patches_[p.patch];
        const double depthFrom = p.largestStretch > 0.0
                                     ? factor * tanR / p.largestStretch
                                     : 0.5;
        for (int side = 0; side < 4; ++side) {
          if (!onEdge(r, side) || !data.collapsed[side] || !data.constantEdge[side]) continue;
          const double along = side == 3   ? p.u
                               : side == 1 ? 1.0 - p.u
                               : side == 0 ? p.v
                                           : 1.0 - p.v;
          const double depth =
              std::min(1.0, std::ceil((along + 2.0 * depthFrom) / kGrid) * kGrid);
          if (side == 3) r.u1 = std::max(r.u0, depth), r.v0 = 0.0, r.v1 = 1.0;
          if (side == 1) r.u0 = std::min(r.u1, 1.0 - depth), r.v0 = 0.0, r.v1 = 1.0;
          if (side == 0) r.v1 = std::max(r.v0, depth), r.u0 = 0.0, r.u1 = 1.0;
          if (side == 2) r.v0 = std::min(r.v1, 1.0 - depth), r.u0 = 0.0, r.u1 = 1.0;
        }
        const std::vector<Rect> assembly = assemble(r);
        if (assembly.size() > 1 &&
            testAssembly(assembly, c, e1, e2, tanR) == CellResult::proven) {
          ++glued_;
          return true;
        }
        if (cells_ >= options_.maxCells) return false;
        if (testAssembly({r}, c, e1, e2, tanR) == CellResult::proven) return true;
      }
    }
    for (const Preimage& p : preimages) {
      const bool seen = std::any_of(tried.begin(), tried.end(), [&](const Preimage& q) {
        return samePreimage(q, p.patch, p.sign, p.u, p.v);
      });
      if (!seen && proveAcrossFold(c, e1, e2, tanR, p)) return true;
    }
    return false;
  }

  // Folds of constant normal: when the preimage p lies near an iso-parameter line u = t or
  // v = t (t dyadic, 2^-kFoldLevels at the finest) along which the patch's normal is constant
  // (the teapot rim's top parallel: the Gauss map folds it to one point), strips t <= u <=
  // t + d (or t - d <= u <= t) the whole line long, grown across glued edges into a ring;
  // the constant side drops out of the boundary (testAssembly), the far sides wind about the
  // fold's image. The preimage's side of the line first, then the other.
  bool proveAcrossFold(const Vec3& c, const Vec3& e1, const Vec3& e2, double tanR,
                       const Preimage& p) {
    for (int axis = 0; axis < 2; ++axis) {
      const double at = axis == 0 ? p.u : p.v;
      double previousLine = -1.0;
      for (int level = 1; level <= kFoldLevels; ++level) {
        const double scale = std::exp2(level);
        const double t = std::round(at * scale) / scale;
        // A fold's strip reaches past the preimage by `across` (below) at most 8 tanR /
        // largestStretch: lines farther away are not tried.
        if (t == previousLine || t <= 0.0 || t >= 1.0) continue;
        if (p.largestStretch > 0.0 && std::abs(at - t) > 8.0 * tanR / p.largestStretch) continue;
        previousLine = t;
        if (!constantLine(p.patch, axis, t)) continue;
        double previousDepth = -1.0;
        for (double factor : {2.0, 4.0, 8.0}) {
          if (cells_ >= options_.maxCells) return false;
          const double across = p.largestStretch > 0.0 ? factor * tanR / p.largestStretch : 0.5;
          const double depth = std::min(
              0.5, std::ceil((std::abs(at - t) + across) / kGrid) * kGrid);
          if (depth == previousDepth) continue;
          previousDepth = depth;
          for (const double side : {at >= t ? 1.0 : -1.0, at >= t ? -1.0 : 1.0}) {
            Rect r;
            r.patch = p.patch;
            r.constantSides = true;
            const double lo = side > 0.0 ? t : std::max(0.0, t - depth);
            const double hi = side > 0.0 ? std::min(1.0, t + depth) : t;
            if (axis == 0) r.u0 = lo, r.u1 = hi; else r.v0 = lo, r.v1 = hi;
            if (testAssembly(assemble(r), c, e1, e2, tanR) == CellResult::proven) {
              ++glued_;
              return true;
            }
          }
        }
      }
    }
    return false;
  }

  // Whether q is constant in direction along the whole line u = t (axis 0) or v = t (axis 1)
  // of the patch: a screen (the certificate is testAssembly's, on each strip's own
  // coefficients), cached.
  bool constantLine(std::size_t patch, int axis, double t) {
    // Cheap screen first: q at the line's two ends (on the patch's edges) parallel.
    const PatchData& data = patches_[patch];
    const Vec3 a = deCasteljau(data.rows[axis == 0 ? 0 : 3], t);
    const Vec3 b = deCasteljau(data.rows[axis == 0 ? 2 : 1], t);
    if (!(norm(cross(a, b)) <= 1e-9 * norm(a) * norm(b) && dot(a, b) > 0.0)) return false;
    const auto key = std::make_tuple(patch, axis, t);
    const auto it = constantLines_.find(key);
    if (it != constantLines_.end()) return it->second;
    std::array<Bernstein2, 3> r;
    for (int k = 0; k < 3; ++k) {
      r[k] = axis == 0 ? restrictTo(data.n[k], t, 1.0, 0.0, 1.0)
                       : restrictTo(data.n[k], 0.0, 1.0, t, 1.0);
    }
    const bool constant = constantRow(edgeRow(r, axis == 0 ? 3 : 0), data.coefficientError);
    constantLines_.emplace(key, constant);
    return constant;
  }

  static double dyadicFloor(double h) { return std::exp2(std::floor(std::log2(h))); }

  // Side k of r lies on patch edge k (0: v = 0, 1: u = 1, 2: v = 1, 3: u = 0).
  static bool onEdge(const Rect& r, int side) {
    switch (side) {
      case 0: return r.v0 == 0.0;
      case 1: return r.u1 == 1.0;
      case 2: return r.v1 == 1.0;
      default: return r.u0 == 0.0;
    }
  }

  // The sides of r, other than `entry`, that lie on a glued edge of its patch and are not
  // glued within the assembly yet.
  std::vector<int> gluableSides(const Rect& r, int entry) const {
    std::vector<int> sides;
    for (int k = 0; k < 4; ++k) {
      if (k == entry || r.glued[k] || !onEdge(r, k)) continue;
      if (patches_[r.patch].collapsed[k] || glues_[r.patch * 4 + k].empty()) continue;
      sides.push_back(k);
    }
    return sides;
  }

  // The rectangle across side `side` of r (on a glued edge): the side's parameter interval
  // mapped to the partner edge, as deep into the partner as r is across the side; its
  // orientation chosen so that the two glued sides cancel in the boundary chain.
  Rect crossSide(const Rect& r, int side, int& entry) const {
    const Glue& g = glues_[r.patch * 4 + side].front();
    const bool alongU = side == 0 || side == 2;
    const double t0 = alongU ? r.u0 : r.v0, t1 = alongU ? r.u1 : r.v1;
    const double depth = alongU ? r.v1 - r.v0 : r.u1 - r.u0;
    const double s0 = g.reversed ? 1.0 - t1 : t0, s1 = g.reversed ? 1.0 - t0 : t1;
    Rect out;
    out.patch = g.patch;
    out.constantSides = r.constantSides;
    switch (g.edge) {
      case 0: out.u0 = s0, out.u1 = s1, out.v0 = 0.0, out.v1 = depth; break;
      case 1: out.u0 = 1.0 - depth, out.u1 = 1.0, out.v0 = s0, out.v1 = s1; break;
      case 2: out.u0 = s0, out.u1 = s1, out.v0 = 1.0 - depth, out.v1 = 1.0; break;
      default: out.u0 = 0.0, out.u1 = depth, out.v0 = s0, out.v1 = s1; break;
    }
    // Counter-clockwise, sides 0 and 1 run with the edge parameter, sides 2 and 3 against.
    const int directionA = side < 2 ? 1 : -1;
    const int mapped = g.reversed ? -directionA : directionA;
    const int directionB = g.edge < 2 ? 1 : -1;
    out.orientation = mapped == directionB ? -r.orientation : r.orientation;
    entry = g.edge;
    return out;
  }

  // r0 and the rectangles reached from it across glued edges: a walk across one glued side
  // after another (each rectangle having exactly one more), closing into a cycle around a
  // vertex (or an apex's strips) when it returns to r0, else a chain, walked both ways.
  std::vector<Rect> assemble(const Rect& r0) const {
    std::vector<Rect> rects{r0};
    const std::vector<int> start = gluableSides(r0, -1);
    bool closed = false;
    for (std::size_t way = 0; way < start.size() && way < 2 && !closed; ++way) {
      std::size_t current = 0;
      int side = start[way];
      if (rects[0].glued[side]) break;
      while (rects.size() < kMaxAssembly) {
        int entry = 0;
        Rect next = crossSide(rects[current], side, entry);
        if (next.same(rects[0])) {
          if (!rects[0].glued[entry] && next.orientation == rects[0].orientation &&
              current != 0) {
            rects[current].glued[side] = true;
            rects[0].glued[entry] = true;
            closed = true;
          }
          break;
        }
        const bool repeated = std::any_of(rects.begin(), rects.end(),
                                          [&](const Rect& x) { return x.same(next); });
        if (repeated) break;
        rects[current].glued[side] = true;
        next.glued[entry] = true;
        rects.push_back(next);
        current = rects.size() - 1;
        const std::vector<int> exits = gluableSides(next, entry);
        if (exits.size() != 1) break;
        side = exits[0];
      }
    }
    return rects;
  }

  // The winding test of an assembly of rectangles for the cap of centre c and chart radius
  // tanR (see the header's steps 1 to 4): each rectangle's normals s n in the chart's
  // hemisphere, every side not glued within the assembly and not an apex row of constant
  // normal sampled, and the sum of their turning angles about 0 (each side's times its
  // rectangle's orientation) a nonzero multiple of 2 pi.
  CellResult testAssembly(const std::vector<Rect>& rects, const Vec3& c, const Vec3& e1,
                          const Vec3& e2, double tanR) {
    struct Prepared {
      std::array<Bernstein2, 3> r;
      Vec3 d;
      double stretch = 0.0;
    };
    std::vector<Prepared> prepared(rects.size());
    for (std::size_t i = 0; i < rects.size(); ++i) {
      ++cells_;
      const Rect& rect = rects[i];
      const PatchData& data = patches_[rect.patch];
      Prepared& pr = prepared[i];
      for (int k = 0; k < 3; ++k) {
        pr.r[k] = restrictTo(data.n[k], rect.u0, rect.u1, rect.v0, rect.v1);
      }
      const Vec3 centre = evaluateVector(pr.r, 0.5, 0.5);
      if (!(norm(centre) > 0.0)) return ++skipped_, CellResult::skipped;
      pr.d = normalized(centre);
      double lower = 0.0, perpendicular = 0.0;
      coneBounds(pr.r, pr.d, data.coefficientError, lower, perpendicular);
      if (!(lower > 0.0)) return ++skipped_, CellResult::skipped;
      // Step 1: the normals lie within rho of d, and s n . c >= cmin > 0.
      const double rho = spreadOf(lower, perpendicular);
      if (rho > options_.maxCellSpreadRad) return CellResult::failed;
      const double sign = dot(pr.d, c) >= 0.0 ? 1.0 : -1.0;
      const double offset = angleBetween(sign * pr.d, c) + 1e-12;
      if (offset + rho > kHalfPi - kChartMargin) return CellResult::failed;
      const double cmin = std::cos(offset + rho) * (1.0 - 1e-12);
      pr.stretch = 1.0 / (cmin * cmin);
    }
    double turn = 0.0, correction = 0.0;
    for (std::size_t i = 0; i < rects.size(); ++i) {
      const Rect& rect = rects[i];
      const PatchData& data = patches_[rect.patch];
      std::array<bool, 4> sampled{};
      for (int side = 0; side < 4; ++side) {
        const bool apex = onEdge(rect, side) && data.collapsed[side] && data.constantEdge[side];
        // A side of constant normal (an apex row, or a fold line of constant normal such as
        // the teapot rim's top parallel): its image is one point, dropped like an apex row.
        sampled[side] = !rect.glued[side] && !apex &&
                        !(rect.constantSides && constantRow(edgeRow(prepared[i].r, side),
                                                            data.coefficientError));
      }
      for (int side = 0; side < 4; ++side) {
        if (!sampled[side]) continue;
        // A side's end shared with a sampled side of the same rectangle is the same computed
        // point (the corner coefficient); elsewhere it meets another rectangle's side or an
        // apex point, and the computed ends may differ by their errors.
        const bool freeStart = !sampled[(side + 3) % 4], freeEnd = !sampled[(side + 1) % 4];
        double sideTurn = 0.0, sideCorrection = 0.0;
        const CellResult r = sampleSide(prepared[i], data, side, c, e1, e2, tanR, freeStart,
                                        freeEnd, sideTurn, sideCorrection);
        if (r != CellResult::proven) return r;
        turn += rect.orientation * sideTurn;
        correction += sideCorrection;
      }
    }
    // Step 4: the sides' images form a cycle (the boundary of the assembly's chain, glued
    // sides cancelled, apex rows being points), so its turning is 2 pi k, k an integer; the
    // computed sum is within `correction` of it (computed vs true ends of the sides).
    if (!(correction < 1.0)) return CellResult::failed;
    const double winding = turn / (2.0 * std::numbers::pi);
    const double rounded = std::round(winding);
    if (std::abs(turn - 2.0 * std::numbers::pi * rounded) > correction + 0.25) {
      return CellResult::failed;  // cannot happen
    }
    return rounded != 0.0 ? CellResult::proven : CellResult::failed;
  }

  // Steps 2 and 3 along one side of a prepared rectangle (counter-clockwise in (u, v); its
  // Bernstein coefficients are the boundary row or column of r, reversed where the parameter
  // runs back). `turn` receives the turning angle of the sampled polygon about 0, and
  // `correction` a bound on the angle between the computed and the true ends that are
  // flagged free.
  CellResult sampleSide(const auto& pr, const PatchData& data, int side, const Vec3& c,
                        const Vec3& e1, const Vec3& e2, double tanR, bool freeStart,
                        bool freeEnd, double& turn, double& correction) {
    const auto& r = pr.r;
    const Vec3& d = pr.d;
    const double stretch = pr.stretch;
    const int m = r[0].degreeU, n = r[0].degreeV;
    auto coefficient = [&](int i, int j) {
      const std::size_t at = static_cast<std::size_t>(i * (n + 1) + j);
      return Vec3{r[0].coefficients[at], r[1].coefficients[at], r[2].coefficients[at]};
    };
    std::vector<Vec3> edge;
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
    turn = 0.0;
    correction = 0.0;
    if (freeStart) correction += std::asin(std::min(1.0, eps / norm(pa)));
    std::vector<std::pair<double, Vec2>> pending;
    for (int k = kInitialSegments; k >= 1; --k) {
      const double t = double(k) / kInitialSegments;
      pending.emplace_back(t, chart(t));
    }
    std::size_t cellSamples = 0;
    while (!pending.empty()) {
      const auto [tb, pb] = pending.back();
      if (!(norm(pa) > tanR + 2.0 * eps)) return CellResult::failed;  // inside the cap
      if (norm(pa) + norm(pb) - 2.0 * tanR - 2.0 * eps > lipschitz * (tb - ta)) {
        // Each turn is below pi: the segment misses the disk about 0.
        turn += std::atan2(cross(pa, pb), dot(pa, pb));
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
    if (!(norm(pa) > tanR + 2.0 * eps)) return CellResult::failed;
    if (freeEnd) correction += std::asin(std::min(1.0, eps / norm(pa)));
    return CellResult::proven;
  }

  // The glue table: every ordered pair of distinct non-collapsed patch edges of equal degree
  // whose q rows are parallel as polynomials (certified by parallelRows), the partner's
  // parameter reversed or not. A cheap test at five parameters screens the pairs first.
  void buildGlues() {
    glues_.assign(patches_.size() * 4, {});
    auto rows = [&](std::size_t edge) -> const std::vector<Vec3>& {
      return patches_[edge / 4].rows[edge % 4];
    };
    for (std::size_t a = 0; a < patches_.size() * 4; ++a) {
      if (patches_[a / 4].collapsed[a % 4]) continue;
      for (std::size_t b = 0; b < patches_.size() * 4; ++b) {
        if (a == b || patches_[b / 4].collapsed[b % 4] || rows(a).size() != rows(b).size()) {
          continue;
        }
        for (bool reversed : {false, true}) {
          std::vector<Vec3> rb = rows(b);
          if (reversed) std::reverse(rb.begin(), rb.end());
          bool close = true;
          for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
            const Vec3 x = deCasteljau(rows(a), t), y = deCasteljau(rb, t);
            close = close && norm(cross(x, y)) <= 1e-9 * norm(x) * norm(y) && norm(x) > 0.0;
          }
          if (!close) continue;
          if (!parallelRows(rows(a), rb, patches_[a / 4].coefficientError,
                            patches_[b / 4].coefficientError)) {
            continue;
          }
          const std::vector<Vec3> ca = edgeControl(*patches_[a / 4].patch, int(a % 4));
          std::vector<Vec3> cb = edgeControl(*patches_[b / 4].patch, int(b % 4));
          if (reversed) std::reverse(cb.begin(), cb.end());
          glues_[a].push_back(Glue{b / 4, int(b % 4), reversed, ca == cb});
        }
      }
      // Shared edges (the surface's own seams) first, then by partner: deterministic.
      std::stable_sort(glues_[a].begin(), glues_[a].end(),
                       [](const Glue& x, const Glue& y) { return x.shared && !y.shared; });
    }
  }

  // True when the polynomials a(t) and b(t) (Bernstein coefficients a_i, b_i, degree d) are
  // parallel: every Bernstein coefficient of a x b, sum over i + j = k of
  // C(d, i) C(d, j) / C(2d, k) (a_i x b_j), is within its rounding bound of zero (the
  // coefficients' own errors ea, eb per component through the products, and the sum's
  // rounding). Then a(t) x b(t) = 0 up to that rounding for all t.
  static bool parallelRows(const std::vector<Vec3>& a, const std::vector<Vec3>& b, double ea,
                           double eb) {
    const int d = static_cast<int>(a.size()) - 1;
    double largestA = 0.0, largestB = 0.0;
    for (const Vec3& x : a) largestA = std::max(largestA, norm(x));
    for (const Vec3& x : b) largestB = std::max(largestB, norm(x));
    for (int k = 0; k <= 2 * d; ++k) {
      Vec3 c{0.0, 0.0, 0.0};
      double absolute = 0.0;
      for (int i = std::max(0, k - d); i <= std::min(k, d); ++i) {
        const double w = binomial(d, i) * binomial(d, k - i) / binomial(2 * d, k);
        c = c + w * cross(a[i], b[k - i]);
        absolute += w * norm(a[i]) * norm(b[k - i]);
      }
      const double tolerance = gamma(2 * d + 12) * absolute +
                               4.0 * kSqrt3 * (ea * largestB + eb * largestA);
      if (!(norm(c) <= tolerance)) return false;
    }
    return true;
  }

  NormalCoverageOptions options_;
  std::vector<std::vector<Glue>> glues_;
  std::vector<PatchData> patches_;
  std::vector<Seed> seeds_;
  std::map<std::tuple<std::size_t, int, double>, bool> constantLines_;
  std::size_t cells_ = 0;
  std::size_t skipped_ = 0;
  std::size_t samples_ = 0;
  std::size_t glued_ = 0;
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
  // Corners where q vanishes as fans (surface.hpp's cornerPieces), their apex rows glued.
  return Prover(cornerResolved(surface), options).run();
}

}  // namespace scallop
