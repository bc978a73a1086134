// Tensor-product Bezier patches: evaluation by differencing and de Casteljau, normals,
// subdivision, and the Bernstein-form polynomials of the normal and the Gaussian curvature.
// See include/scallop/bezier.hpp for the contract.

#include "scallop/geometry/bezier.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>
#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/geometry/tolerances.hpp"

namespace scallop {
namespace {


void requireValid(const BezierPatch& patch, const char* what) {
  if (patch.degreeU < 1 || patch.degreeV < 1) {
    throw Error(fmt::format("{}: a Bezier patch needs degrees >= 1, got ({}, {})", what,
                            patch.degreeU, patch.degreeV));
  }
  const std::size_t expected =
      static_cast<std::size_t>(patch.degreeU + 1) * static_cast<std::size_t>(patch.degreeV + 1);
  if (patch.control.size() != expected) {
    throw Error(fmt::format("{}: bidegree ({}, {}) needs {} control points, got {}", what,
                            patch.degreeU, patch.degreeV, expected, patch.control.size()));
  }
  if (patch.rational()) {
    if (patch.weights.size() != expected)
      throw Error(fmt::format("{}: bidegree ({}, {}) needs {} weights, got {}", what, patch.degreeU,
                              patch.degreeV, expected, patch.weights.size()));
    for (std::size_t i = 0; i < expected; ++i)
      if (!(patch.weights[i] > 0.0) || !std::isfinite(patch.weights[i]))
        throw Error(fmt::format("{}: weight {} is {}; a rational patch's weights must be positive and finite", what,
                                i, patch.weights[i]));
  }
}

// In-place de Casteljau on b[0 .. n]; returns the point at t.
Vec3 deCasteljau(Vec3* b, int n, double t) {
  const double s = 1.0 - t;
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i <= n - r; ++i) b[i] = s * b[i] + t * b[i + 1];
  }
  return b[0];
}

// n (n - 1) .. (n - d + 1)
double fallingFactorial(int n, int d) {
  double f = 1.0;
  for (int i = 0; i < d; ++i) f *= n - i;
  return f;
}

// The (du, dv) partial derivative at (u, v): difference the control net dv times along v
// and du times along u, evaluate each row in v and the resulting column in u (de Casteljau),
// and multiply by m!/(m-du)! n!/(n-dv)!. Differencing first keeps the derivative's rounding
// relative to the differences, not to the coordinates.
// M, N, DU, DV >= 0 fix the degrees and orders at compile time (the bicubic patches the
// drop envelope's Newton steps evaluate millions of times): the same operations in the same
// order, so the same bits, unrolled.
template <int M = -1, int N = -1, int DU = -1, int DV = -1>
Vec3 partialImpl(const BezierPatch& patch, double u, double v, int duRuntime, int dvRuntime) {
  constexpr bool kFixed = M >= 0;
  const int m = kFixed ? M : patch.degreeU;
  const int n = kFixed ? N : patch.degreeV;
  const int du = kFixed ? DU : duRuntime;
  const int dv = kFixed ? DV : dvRuntime;
  if (du > m || dv > n) return {};
  const int stride = n + 1;
  constexpr std::size_t kSmall = kFixed ? static_cast<std::size_t>((M + 1) * (N + 1)) : 36;
  std::array<Vec3, kSmall> small;  // up to bidegree (5, 5) without allocation; overwritten
  std::vector<Vec3> large;
  Vec3* net = small.data();
  if (!kFixed && patch.control.size() > kSmall) {
    large.resize(patch.control.size());
    net = large.data();
  }
  if constexpr (kFixed) {
    std::copy_n(patch.control.begin(), kSmall, net);  // all of `small`, visibly
  } else {
    std::copy(patch.control.begin(), patch.control.end(), net);
  }
  for (int j = 0; j <= m; ++j) {
    Vec3* row = net + j * stride;
    for (int d = 1; d <= dv; ++d) {
      for (int k = 0; k <= n - d; ++k) row[k] = row[k + 1] - row[k];
    }
  }
  for (int d = 1; d <= du; ++d) {
    for (int j = 0; j <= m - d; ++j) {
      for (int k = 0; k <= n - dv; ++k)
        net[j * stride + k] = net[(j + 1) * stride + k] - net[j * stride + k];
    }
  }
  // Row j's value lands in net[j * stride]; gathering it into net[j] only overwrites entries
  // already used (net[j] lies in row 0, or is the source of an earlier row j / stride).
  for (int j = 0; j <= m - du; ++j) net[j] = deCasteljau(net + j * stride, n - dv, v);
  return (fallingFactorial(m, du) * fallingFactorial(n, dv)) * deCasteljau(net, m - du, u);
}

Vec3 partial(const BezierPatch& patch, double u, double v, int du, int dv) {
  if (patch.degreeU == 3 && patch.degreeV == 3 && patch.control.size() == 16 && du >= 0 &&
      dv >= 0 && du + dv <= 2) {
    switch (du * 3 + dv) {
      case 0: return partialImpl<3, 3, 0, 0>(patch, u, v, 0, 0);
      case 1: return partialImpl<3, 3, 0, 1>(patch, u, v, 0, 1);
      case 3: return partialImpl<3, 3, 1, 0>(patch, u, v, 1, 0);
      case 2: return partialImpl<3, 3, 0, 2>(patch, u, v, 0, 2);
      case 4: return partialImpl<3, 3, 1, 1>(patch, u, v, 1, 1);
      case 6: return partialImpl<3, 3, 2, 0>(patch, u, v, 2, 0);
      default: break;
    }
  }
  return partialImpl<>(patch, u, v, du, dv);
}


// r and its partials to second order of a rational patch by the quotient rule (see the
// contract); defined below, beside derivativesToSecondOrder's sums.
PatchDerivatives rationalDerivatives(const BezierPatch& patch, double u, double v, Vec3* value);

// partial() of any patch: the polynomial's own, or the rational's by the quotient rule.
Vec3 anyPartial(const BezierPatch& patch, double u, double v, int du, int dv) {
  if (!patch.rational()) return partial(patch, u, v, du, dv);
  Vec3 value;
  const PatchDerivatives d = rationalDerivatives(patch, u, v, &value);
  switch (du * 3 + dv) {
    case 0: return value;
    case 1: return d.v;
    case 3: return d.u;
    case 2: return d.vv;
    case 4: return d.uv;
    case 6: return d.uu;
    default: break;
  }
  throw Error(fmt::format("a rational patch's partial derivative of order ({}, {}): only up to the second", du, dv));
}

// B_j^d(t), dB_j^d/dt and d2B_j^d/dt2 for j = 0..d: the basis of degree d - 2 by the
// triangle b^e_j = (1 - t) b^(e-1)_j + t b^(e-1)_(j-1), raised to d - 1 and d, with
//   d/dt B_j^d = d (B_(j-1)^(d-1) - B_j^(d-1)),
//   d2/dt2 B_j^d = d (d - 1) (B_(j-2)^(d-2) - 2 B_(j-1)^(d-2) + B_j^(d-2))
// (terms with an index outside 0..degree are 0).
// Written into value[0..d], first[0..d] and second[0..d]: the triangle runs in place in
// `value`, and the bases of degree d - 1 and d - 2 are kept in `first` and `second` on the
// way, then differenced in place from the top index down (each entry reads only entries at
// or below its own index, not yet overwritten). D >= 0 fixes d at compile time (the same
// operations, unrolled).
template <int D = -1>
void basisDerivatives(int dRuntime, double t, double* value, double* first, double* second) {
  const int d = D >= 0 ? D : dRuntime;
  value[0] = 1.0;
  auto keep = [&](int e) {  // value[0..e] holds the basis of degree e
    if (e == d - 2) std::copy(value, value + e + 1, second);
    if (e == d - 1) std::copy(value, value + e + 1, first);
  };
  keep(0);
  for (int e = 1; e <= d; ++e) {
    value[e] = t * value[e - 1];
    for (int j = e - 1; j >= 1; --j) value[j] = (1.0 - t) * value[j] + t * value[j - 1];
    value[0] = (1.0 - t) * value[0];
    keep(e);
  }
  auto at = [](const double* c, int size, int j) { return j >= 0 && j < size ? c[j] : 0.0; };
  for (int j = d; j >= 0; --j) first[j] = d >= 1 ? d * (at(first, d, j - 1) - at(first, d, j)) : 0.0;
  for (int j = d; j >= 0; --j) {
    second[j] = d >= 2 ? d * (d - 1) * (at(second, d - 1, j - 2) - 2.0 * at(second, d - 1, j - 1) + at(second, d - 1, j))
                       : 0.0;
  }
}

BezierPatch fromCoordinates(const std::array<Bernstein2, 3>& xyz) {
  BezierPatch patch{xyz[0].degreeU, xyz[0].degreeV, std::vector<Vec3>(xyz[0].coefficients.size())};
  for (std::size_t i = 0; i < patch.control.size(); ++i) {
    patch.control[i] = {xyz[0].coefficients[i], xyz[1].coefficients[i], xyz[2].coefficients[i]};
  }
  return patch;
}

template <class F>
BezierPatch mapCoordinates(const BezierPatch& patch, F f) {
  if (patch.rational()) {
    // On the homogeneous net (X, w): the weights stay positive under subdivision (convex
    // combinations), and the points are X / w.
    const std::array<Bernstein2, 4> h = homogeneousPolynomials(patch);
    const Bernstein2 w = f(h[3]);
    BezierPatch out = fromCoordinates({f(h[0]), f(h[1]), f(h[2])});
    out.weights = w.coefficients;
    for (std::size_t i = 0; i < out.control.size(); ++i) out.control[i] = out.control[i] / out.weights[i];
    return out;
  }
  const std::array<Bernstein2, 3> xyz = coordinatePolynomials(patch);
  return fromCoordinates({f(xyz[0]), f(xyz[1]), f(xyz[2])});
}

Bernstein2 dot(const std::array<Bernstein2, 3>& a, const std::array<Bernstein2, 3>& b) {
  return add(add(multiply(a[0], b[0]), multiply(a[1], b[1])), multiply(a[2], b[2]));
}

std::array<Bernstein2, 3> derivativesU(const std::array<Bernstein2, 3>& r) {
  return {derivativeU(r[0]), derivativeU(r[1]), derivativeU(r[2])};
}

std::array<Bernstein2, 3> derivativesV(const std::array<Bernstein2, 3>& r) {
  return {derivativeV(r[0]), derivativeV(r[1]), derivativeV(r[2])};
}

}  // namespace

Vec3 point(const BezierPatch& patch, double u, double v) {
  requireValid(patch, "point");
  return anyPartial(patch, u, v, 0, 0);
}

Vec3 derivativeU(const BezierPatch& patch, double u, double v) {
  requireValid(patch, "derivativeU");
  return anyPartial(patch, u, v, 1, 0);
}

Vec3 derivativeV(const BezierPatch& patch, double u, double v) {
  requireValid(patch, "derivativeV");
  return anyPartial(patch, u, v, 0, 1);
}

Vec3 secondDerivative(const BezierPatch& patch, double u, double v, int du, int dv) {
  requireValid(patch, "secondDerivative");
  if (du < 0 || dv < 0 || du + dv != 2) {
    throw Error(fmt::format(
        "secondDerivative: orders (du, dv) must be (2, 0), (1, 1) or (0, 2), got ({}, {})", du,
        dv));
  }
  return anyPartial(patch, u, v, du, dv);
}

// r_u x r_v: two partials of a polynomial patch; one quotient-rule pass of a rational one.
Vec3 firstDerivativesCross(const BezierPatch& patch, double u, double v) {
  if (patch.rational()) {
    const PatchDerivatives d = rationalDerivatives(patch, u, v, nullptr);
    return cross(d.u, d.v);
  }
  return cross(partial(patch, u, v, 1, 0), partial(patch, u, v, 0, 1));
}

Vec3 normalVector(const BezierPatch& patch, double u, double v) {
  requireValid(patch, "normalVector");
  return firstDerivativesCross(patch, u, v);
}

double normalRoundingThreshold(const BezierPatch& patch) {
  requireValid(patch, "normalRoundingThreshold");
  const int m = patch.degreeU;
  const int n = patch.degreeV;
  // S_u = m max|p_{j+1,k} - p_jk| >= |r_u| and likewise S_v >= |r_v| on the patch (m times a
  // convex combination of the differences). The computed r_u is within
  // gamma_{3(m+n)+2} S_u of the exact one (differences, de Casteljau, the degree factor),
  // likewise r_v, and the cross product adds 3u |r_u||r_v|: below (6(m + n) + 8) u S_u S_v
  // the computed normal may be rounding noise, and its direction meaningless.
  auto squaredNorm = [](const Vec3& d) { return dot(d, d); };
  if (patch.rational()) {
    // |r_u| <= (|X_u| + |w_u| |r|) / w <= (m max|dX| + m max|dw| max|p|) / min w (the
    // quotient rule; r in the control points' convex hull), likewise r_v; the divisions and
    // the quotient rule's products add a few roundings more than the polynomial case's.
    double dxu = 0.0, dxv = 0.0, dwu = 0.0, dwv = 0.0, largest = 0.0, least = patch.weights[0];
    for (int j = 0; j <= m; ++j) {
      for (int k = 0; k <= n; ++k) {
        const double w = patch.weight(j, k);
        const Vec3 x = w * patch.at(j, k);
        largest = std::max(largest, norm(patch.at(j, k)));
        least = std::min(least, w);
        if (j < m) {
          dxu = std::max(dxu, norm(patch.weight(j + 1, k) * patch.at(j + 1, k) - x));
          dwu = std::max(dwu, std::abs(patch.weight(j + 1, k) - w));
        }
        if (k < n) {
          dxv = std::max(dxv, norm(patch.weight(j, k + 1) * patch.at(j, k + 1) - x));
          dwv = std::max(dwv, std::abs(patch.weight(j, k + 1) - w));
        }
      }
    }
    const double su = m * (dxu + dwu * largest) / least;
    const double sv = n * (dxv + dwv * largest) / least;
    return (6.0 * (m + n) + 16.0) * kUnitRoundoff * su * sv;
  }
  double su2 = 0.0;  // the squares (one square root each below: sqrt is monotone)
  double sv2 = 0.0;
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k <= n; ++k) {
      if (j < m) su2 = std::max(su2, squaredNorm(patch.at(j + 1, k) - patch.at(j, k)));
      if (k < n) sv2 = std::max(sv2, squaredNorm(patch.at(j, k + 1) - patch.at(j, k)));
    }
  }
  const double su = std::sqrt(su2);
  const double sv = std::sqrt(sv2);
  return (6.0 * (m + n) + 8.0) * kUnitRoundoff * (m * su) * (n * sv);
}

namespace {
// How far from a corner unitNormal takes the ray limit where q is below rounding: q's zero at
// the corner is simple, so |q| ~ |q_u| |(du, dv)| exceeds the threshold well inside this.
constexpr double kCornerRayRadius = 1e-6;
}  // namespace

Vec3 unitNormal(const BezierPatch& patch, double u, double v) {
  requireValid(patch, "unitNormal");
  const Vec3 normal = firstDerivativesCross(patch, u, v);
  const double length = norm(normal);
  const double threshold = normalRoundingThreshold(patch);
  if (length > threshold) return normal / length;
  // On (or within rounding of) a collapsed edge the normal is the limit q / |q| of the
  // direction field N = u^a (1 - u)^b v^c (1 - v)^d q (normalDirectionPolynomials): rare
  // points, so the Bernstein forms are built here rather than kept.
  const NormalDirection direction = normalDirectionPolynomials(patch);
  const std::array<Bernstein2, 3>& q = direction.polynomials;
  const double cu = std::clamp(u, 0.0, 1.0), cv = std::clamp(v, 0.0, 1.0);
  if (direction.powers.any()) {
    const Vec3 value{evaluate(q[0], cu, cv), evaluate(q[1], cu, cv), evaluate(q[2], cu, cv)};
    const double qLength = norm(value);
    if (qLength > threshold) return value / qLength;
  }
  // Within rounding of a corner where q itself vanishes (surface.hpp's cornerPieces: q =
  // du q_u + dv q_v + O(|(du, dv)|^2) there): the limit along the ray from the corner
  // through (u, v), at the corner itself along the diagonal into the patch.
  const double u0 = cu < 0.5 ? 0.0 : 1.0, v0 = cv < 0.5 ? 0.0 : 1.0;
  if (std::hypot(cu - u0, cv - v0) <= kCornerRayRadius) {
    double du = cu - u0, dv = cv - v0;
    if (du == 0.0 && dv == 0.0) du = 1.0 - 2.0 * u0, dv = 1.0 - 2.0 * v0;
    const double rayScale = std::hypot(du, dv);
    du /= rayScale, dv /= rayScale;
    Vec3 ray;
    for (std::size_t c = 0; c < 3; ++c) {
      const double slope = du * evaluate(derivativeU(q[c]), u0, v0) + dv * evaluate(derivativeV(q[c]), u0, v0);
      (c == 0 ? ray.x : c == 1 ? ray.y : ray.z) = slope;
    }
    const double rayLength = norm(ray);
    if (rayLength > threshold) return ray / rayLength;
  }
  throw Error(fmt::format(
      "unitNormal: r_u x r_v vanishes at (u, v) = ({}, {}); the patch is not regular there", u, v));
}

std::pair<BezierPatch, BezierPatch> subdivideU(const BezierPatch& patch, double t) {
  requireValid(patch, "subdivideU");
  return {mapCoordinates(patch, [t](const Bernstein2& c) { return subdivideU(c, t).first; }),
          mapCoordinates(patch, [t](const Bernstein2& c) { return subdivideU(c, t).second; })};
}

std::pair<BezierPatch, BezierPatch> subdivideV(const BezierPatch& patch, double t) {
  requireValid(patch, "subdivideV");
  return {mapCoordinates(patch, [t](const Bernstein2& c) { return subdivideV(c, t).first; }),
          mapCoordinates(patch, [t](const Bernstein2& c) { return subdivideV(c, t).second; })};
}

BezierPatch restrictTo(const BezierPatch& patch, double u0, double u1, double v0, double v1) {
  requireValid(patch, "restrictTo");
  return mapCoordinates(patch, [&](const Bernstein2& c) { return restrictTo(c, u0, u1, v0, v1); });
}

std::array<Bernstein2, 4> homogeneousPolynomials(const BezierPatch& patch) {
  requireValid(patch, "homogeneousPolynomials");
  std::array<Bernstein2, 4> xyzw;
  for (Bernstein2& c : xyzw) {
    c.degreeU = patch.degreeU;
    c.degreeV = patch.degreeV;
    c.coefficients.resize(patch.control.size());
  }
  for (std::size_t i = 0; i < patch.control.size(); ++i) {
    const double w = patch.rational() ? patch.weights[i] : 1.0;
    xyzw[0].coefficients[i] = w * patch.control[i].x;
    xyzw[1].coefficients[i] = w * patch.control[i].y;
    xyzw[2].coefficients[i] = w * patch.control[i].z;
    xyzw[3].coefficients[i] = w;
  }
  return xyzw;
}

std::array<Bernstein2, 3> coordinatePolynomials(const BezierPatch& patch) {
  requireValid(patch, "coordinatePolynomials");
  if (patch.rational())
    throw Error("coordinatePolynomials: the patch is rational (its coordinates are quotients); this computation "
                "takes polynomial patches only");
  std::array<Bernstein2, 3> xyz;
  for (Bernstein2& c : xyz) {
    c.degreeU = patch.degreeU;
    c.degreeV = patch.degreeV;
    c.coefficients.resize(patch.control.size());
  }
  for (std::size_t i = 0; i < patch.control.size(); ++i) {
    xyz[0].coefficients[i] = patch.control[i].x;
    xyz[1].coefficients[i] = patch.control[i].y;
    xyz[2].coefficients[i] = patch.control[i].z;
  }
  return xyz;
}

namespace {

std::array<Bernstein2, 3> crossPolynomials(const std::array<Bernstein2, 3>& a, const std::array<Bernstein2, 3>& b) {
  return {subtract(multiply(a[1], b[2]), multiply(a[2], b[1])), subtract(multiply(a[2], b[0]), multiply(a[0], b[2])),
          subtract(multiply(a[0], b[1]), multiply(a[1], b[0]))};
}

std::array<Bernstein2, 3> scaled(const Bernstein2& s, const std::array<Bernstein2, 3>& a) {
  return {multiply(s, a[0]), multiply(s, a[1]), multiply(s, a[2])};
}

std::array<Bernstein2, 3> minus(const std::array<Bernstein2, 3>& a, const std::array<Bernstein2, 3>& b) {
  return {subtract(a[0], b[0]), subtract(a[1], b[1]), subtract(a[2], b[2])};
}

// The homogeneous X (x, y, z) and w of a rational patch.
struct Homogeneous {
  std::array<Bernstein2, 3> x;
  Bernstein2 w;
};

Homogeneous homogeneousOf(const BezierPatch& patch) {
  const std::array<Bernstein2, 4> h = homogeneousPolynomials(patch);
  return {{h[0], h[1], h[2]}, h[3]};
}

// N = w X_u x X_v - w_v X_u x X - w_u X x X_v (the contract's Rational patches).
std::array<Bernstein2, 3> rationalNormalPolynomials(const Homogeneous& h) {
  const std::array<Bernstein2, 3> xu = derivativesU(h.x), xv = derivativesV(h.x);
  const Bernstein2 wu = derivativeU(h.w), wv = derivativeV(h.w);
  return minus(minus(scaled(h.w, crossPolynomials(xu, xv)), scaled(wv, crossPolynomials(xu, h.x))),
               scaled(wu, crossPolynomials(h.x, xv)));
}

}  // namespace

std::array<Bernstein2, 3> normalPolynomials(const BezierPatch& patch) {
  if (patch.rational()) return rationalNormalPolynomials(homogeneousOf(patch));
  const std::array<Bernstein2, 3> r = coordinatePolynomials(patch);
  const std::array<Bernstein2, 3> ru = derivativesU(r);  // (m - 1, n)
  const std::array<Bernstein2, 3> rv = derivativesV(r);  // (m, n - 1)
  return {subtract(multiply(ru[1], rv[2]), multiply(ru[2], rv[1])),
          subtract(multiply(ru[2], rv[0]), multiply(ru[0], rv[2])),
          subtract(multiply(ru[0], rv[1]), multiply(ru[1], rv[0]))};
}

namespace {

// (r_uu . N)(r_vv . N) - (r_uv . N)^2 and a bound on its terms' size,
// |r_uu . N| |r_vv . N| + |r_uv . N|^2 (their coefficients' largest magnitudes).
std::pair<Bernstein2, double> curvatureNumeratorAndBound(const BezierPatch& patch) {
  auto largest = [](const Bernstein2& p) {
    double out = 0.0;
    for (double c : p.coefficients) out = std::max(out, std::abs(c));
    return out;
  };
  if (patch.rational()) {
    // A B - C^2 with A = w X_uu . N - w_uu X . N, and so on (the contract).
    const Homogeneous h = homogeneousOf(patch);
    const std::array<Bernstein2, 3> normal = rationalNormalPolynomials(h);
    const Bernstein2 xn = dot(h.x, normal);
    const std::array<Bernstein2, 3> xu = derivativesU(h.x);
    const Bernstein2 wu = derivativeU(h.w);
    const Bernstein2 mixed =
        subtract(multiply(h.w, dot(derivativesV(xu), normal)), multiply(derivativeV(wu), xn));
    const Bernstein2 mixedSquared = multiply(mixed, mixed);
    if (patch.degreeU < 2 || patch.degreeV < 2) return {scale(mixedSquared, -1.0), largest(mixed) * largest(mixed)};
    const Bernstein2 uu = subtract(multiply(h.w, dot(derivativesU(xu), normal)), multiply(derivativeU(wu), xn));
    const std::array<Bernstein2, 3> xv = derivativesV(h.x);
    const Bernstein2 wv = derivativeV(h.w);
    const Bernstein2 vv = subtract(multiply(h.w, dot(derivativesV(xv), normal)), multiply(derivativeV(wv), xn));
    return {subtract(multiply(uu, vv), mixedSquared), largest(uu) * largest(vv) + largest(mixed) * largest(mixed)};
  }
  const std::array<Bernstein2, 3> r = coordinatePolynomials(patch);
  const std::array<Bernstein2, 3> normal = normalPolynomials(patch);  // (2m - 1, 2n - 1)
  const std::array<Bernstein2, 3> ru = derivativesU(r);
  const std::array<Bernstein2, 3> ruv = derivativesV(ru);  // (m - 1, n - 1)
  const Bernstein2 mixed = dot(ruv, normal);               // (3m - 2, 3n - 2)
  const Bernstein2 mixedSquared = multiply(mixed, mixed);  // (6m - 4, 6n - 4)
  // r_uu (m - 2, n) and r_vv (m, n - 2) vanish identically for m = 1 or n = 1; leaving the
  // product out then keeps the bidegree (6m - 4, 6n - 4) instead of padding it.
  if (patch.degreeU < 2 || patch.degreeV < 2) {
    return {scale(mixedSquared, -1.0), largest(mixed) * largest(mixed)};
  }
  const Bernstein2 uu = dot(derivativesU(ru), normal);               // (3m - 3, 3n - 1)
  const Bernstein2 vv = dot(derivativesV(derivativesV(r)), normal);  // (3m - 1, 3n - 3)
  return {subtract(multiply(uu, vv), mixedSquared),                  // (6m - 4, 6n - 4)
          largest(uu) * largest(vv) + largest(mixed) * largest(mixed)};
}

}  // namespace

Bernstein2 gaussianCurvatureNumerator(const BezierPatch& patch) {
  return curvatureNumeratorAndBound(patch).first;
}

Bernstein2 normalLengthSquared(const BezierPatch& patch) {
  const std::array<Bernstein2, 3> normal = normalPolynomials(patch);
  return dot(normal, normal);
}

NormalDirection normalDirectionPolynomials(const BezierPatch& patch) {
  NormalDirection out;
  const std::array<Bernstein2, 3> normal = normalPolynomials(patch);
  const std::vector<Bernstein2> quotients = divideEdgeFactors(
      {normal[0], normal[1], normal[2]}, normalRoundingThreshold(patch), out.powers);
  out.polynomials = {quotients[0], quotients[1], quotients[2]};
  return out;
}

CurvatureSign curvatureSignPolynomial(const BezierPatch& patch) {
  // A row or column of K's coefficients below 1e-12 of the terms' bound vanishes but for
  // rounding.
  const auto [numerator, termBound] = curvatureNumeratorAndBound(patch);
  CurvatureSign out;
  out.polynomial = divideEdgeFactors({numerator}, 1e-12 * termBound, out.powers).front();
  return out;
}

namespace {

// The Bernstein bases of a patch's two directions at (u, v) with their first and second
// derivatives: three rows per direction (value, first, second), su and sv apart; on the stack
// up to degree 20 (a surface's largest, kMaxPatchDegree in surface.hpp: the distance search
// evaluates such patches millions of times), on the heap past it. M, N >= 0 fix the degrees
// at compile time. Not copyable: bu points into it.
template <int M = -1, int N = -1>
struct BasisTable {
  static constexpr int kSmall = 21;
  int m, n, su, sv;
  std::array<double, 6 * kSmall> small;
  std::vector<double> large;
  double* bu;
  double* bv;
  BasisTable(const BezierPatch& patch, double u, double v)
      : m(M >= 0 ? M : patch.degreeU), n(N >= 0 ? N : patch.degreeV) {
    const bool onStack = std::max(m, n) < kSmall;
    su = onStack ? kSmall : m + 1;
    sv = onStack ? kSmall : n + 1;
    bu = small.data();
    if (!onStack) {
      large.resize(3 * static_cast<std::size_t>(su + sv));
      bu = large.data();
    }
    bv = bu + 3 * su;
    basisDerivatives<M>(m, u, bu, bu + su, bu + 2 * su);
    basisDerivatives<N>(n, v, bv, bv + sv, bv + 2 * sv);
  }
  BasisTable(const BasisTable&) = delete;
  BasisTable& operator=(const BasisTable&) = delete;
};

// derivativesToSecondOrder's sums, and r itself into *value when asked (the row sums with
// the v basis weighed by the u basis); M, N >= 0 fix the degrees at compile time (the same
// operations in the same order, unrolled).
template <int M = -1, int N = -1>
PatchDerivatives derivativesImpl(const BezierPatch& patch, double u, double v, Vec3* value = nullptr) {
  const BasisTable<M, N> basis(patch, u, v);
  const int m = M >= 0 ? M : basis.m;  // constants when fixed: the loops below unroll
  const int n = N >= 0 ? N : basis.n;
  const int su = basis.su, sv = basis.sv;
  const double* bu = basis.bu;
  const double* bv = basis.bv;
  PatchDerivatives out{};
  Vec3 r{};
  for (int j = 0; j <= m; ++j) {
    Vec3 row0{}, row1{}, row2{};  // the row's sums with the v basis and its derivatives
    for (int k = 0; k <= n; ++k) {
      const Vec3& p = patch.at(j, k);
      row0 = row0 + bv[k] * p;
      row1 = row1 + bv[sv + k] * p;
      row2 = row2 + bv[2 * sv + k] * p;
    }
    if (value != nullptr) r = r + bu[j] * row0;  // only when asked: the other callers are hot too
    out.u = out.u + bu[su + j] * row0;
    out.v = out.v + bu[j] * row1;
    out.uu = out.uu + bu[2 * su + j] * row0;
    out.uv = out.uv + bu[su + j] * row1;
    out.vv = out.vv + bu[j] * row2;
  }
  if (value != nullptr) *value = r;
  return out;
}

// The same sums over the homogeneous net (X_jk = w_jk p_jk and w_jk) in one pass, then the
// quotient rule: r = X / w, r_u = (X_u - w_u r) / w, r_uu = (X_uu - 2 w_u r_u - w_uu r) / w,
// r_uv = (X_uv - w_u r_v - w_v r_u - w_uv r) / w, and likewise in v.
template <int M = -1, int N = -1>
PatchDerivatives rationalImpl(const BezierPatch& patch, double u, double v, Vec3* value) {
  const BasisTable<M, N> basis(patch, u, v);
  const int m = M >= 0 ? M : basis.m;  // constants when fixed: the loops below unroll
  const int n = N >= 0 ? N : basis.n;
  const int su = basis.su, sv = basis.sv;
  const double* bu = basis.bu;
  const double* bv = basis.bv;
  Vec3 x{}, xu{}, xv{}, xuu{}, xuv{}, xvv{};
  double w = 0.0, wu = 0.0, wv = 0.0, wuu = 0.0, wuv = 0.0, wvv = 0.0;
  for (int j = 0; j <= m; ++j) {
    Vec3 row0{}, row1{}, row2{};
    double weight0 = 0.0, weight1 = 0.0, weight2 = 0.0;
    for (int k = 0; k <= n; ++k) {
      const double wk = patch.weight(j, k);
      const Vec3 p = wk * patch.at(j, k);
      row0 = row0 + bv[k] * p;
      row1 = row1 + bv[sv + k] * p;
      row2 = row2 + bv[2 * sv + k] * p;
      weight0 += bv[k] * wk;
      weight1 += bv[sv + k] * wk;
      weight2 += bv[2 * sv + k] * wk;
    }
    x = x + bu[j] * row0;
    xu = xu + bu[su + j] * row0;
    xv = xv + bu[j] * row1;
    xuu = xuu + bu[2 * su + j] * row0;
    xuv = xuv + bu[su + j] * row1;
    xvv = xvv + bu[j] * row2;
    w += bu[j] * weight0;
    wu += bu[su + j] * weight0;
    wv += bu[j] * weight1;
    wuu += bu[2 * su + j] * weight0;
    wuv += bu[su + j] * weight1;
    wvv += bu[j] * weight2;
  }
  const Vec3 r = x / w;
  PatchDerivatives d{};
  d.u = (xu - wu * r) / w;
  d.v = (xv - wv * r) / w;
  d.uu = (xuu - 2.0 * wu * d.u - wuu * r) / w;
  d.uv = (xuv - wu * d.v - wv * d.u - wuv * r) / w;
  d.vv = (xvv - 2.0 * wv * d.v - wvv * r) / w;
  if (value) *value = r;
  return d;
}

PatchDerivatives rationalDerivatives(const BezierPatch& patch, double u, double v, Vec3* value) {
  if (patch.degreeU == 3 && patch.degreeV == 3) return rationalImpl<3, 3>(patch, u, v, value);
  return rationalImpl<>(patch, u, v, value);
}

}  // namespace

PatchDerivatives derivativesToSecondOrder(const BezierPatch& patch, double u, double v) {
  requireValid(patch, "derivativesToSecondOrder");
  if (patch.rational()) return rationalDerivatives(patch, u, v, nullptr);
  if (patch.degreeU == 3 && patch.degreeV == 3) return derivativesImpl<3, 3>(patch, u, v);
  return derivativesImpl<>(patch, u, v);
}

PatchDerivatives derivativesToSecondOrder(const BezierPatch& patch, double u, double v, Vec3& value) {
  requireValid(patch, "derivativesToSecondOrder");
  if (patch.rational()) return rationalDerivatives(patch, u, v, &value);
  if (patch.degreeU == 3 && patch.degreeV == 3) return derivativesImpl<3, 3>(patch, u, v, &value);
  return derivativesImpl<>(patch, u, v, &value);
}

double gaussianCurvatureNumeratorAt(const BezierPatch& patch, double u, double v) {
  const PatchDerivatives d = derivativesToSecondOrder(patch, u, v);
  const Vec3 n = cross(d.u, d.v);
  const double l = dot(d.uu, n);
  const double m = dot(d.uv, n);
  const double nn = dot(d.vv, n);
  return l * nn - m * m;
}

}  // namespace scallop
