// Tests for bezier.hpp: tensor-product Bezier patches, their normals and the Bernstein forms
// of the normal, the Gaussian-curvature numerator and the squared normal length.
//
// References, all written in this file and independent of src/:
//  - the patch and its partial derivatives as explicit sums sum_jk p_jk b_j^(a)(u) b_k^(b)(v)
//    in long double, the basis derivatives by Leibniz' rule on C(n,i) t^i (1 - t)^(n-i);
//  - the Gaussian curvature from the fundamental forms, K = (LN - M^2) / (EG - F^2), with
//    E = r_u.r_u, F = r_u.r_v, G = r_v.r_v, L = r_uu.n, M = r_uv.n, N = r_vv.n, n the unit
//    normal, all from the reference derivatives;
//  - closed forms for a plane, a parabolic cylinder, a saddle and an elliptic cap.
//
// Tolerances (u = 2^-53, uL = long double's unit roundoff, gamma(k) = k u / (1 - k u)).
// bezier.hpp evaluates a partial derivative of order (a, b) by differencing the net (v first,
// then u), de Casteljau, and one product by F = m!/(m-a)! n!/(n-b)!. A first difference rounds
// once relative to itself; a second difference adds one rounding relative to the sum of the
// two first differences it combines. So with A_jk the "absolute differences" (|p| for order 0,
// |first difference| for order 1, the sum of the two |first differences| for order 2), the
// computed derivative is within gamma(3(m + n) + 4) F sum_jk A_jk b_j(u) b_k(v) (differences 2,
// de Casteljau 3(m + n) at most, the product by F 1, and slack 1), per coordinate.
// The polynomial views are products and sums of Bernstein forms; their bounds are the
// bernstein.hpp contract bounds chained through the construction (derived next to each test),
// times the corresponding "absolute" polynomials evaluated here.
// The reference's own error: an explicit sum in long double is within (4(m + n) + 16) uL of
// the sum with |terms| (binomials exact, powers by repeated products, as in
// bernstein_test.cpp); expressions built from reference values add a few uL per operation.
//
// Tests (gtest suite names):
//  BezierEvaluate    point and all partials up to order 2, bidegrees 1..5 (bicubic weighted);
//  BezierNormal      normal polynomials vs r_u x r_v, unit normal, |N|^2 and the regularity
//                    proof, degenerate patches (collinear net, collapsed row) throwing, the
//                    normal-cone certificate of bezier.hpp;
//  BezierCurvature   numerator vs K (LN - M^2) / (EG - F^2), parabolic lines vs the quadtree
//                    test, plane / cylinder / saddle / cap / tilted plane, degrees, scaling;
//  BezierSubdivide, BezierErrors.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/bezier.hpp"
#include "scallop/error.hpp"
#include "scallop/geometry/vector.hpp"
#include "support/rational_patches.hpp"

namespace {

using scallop::Bernstein2;
using scallop::BezierPatch;
using scallop::Vec3;
using Real = long double;

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;
constexpr Real kUL = std::numeric_limits<Real>::epsilon() / 2;

double gamma(int k) { return k * kU / (1.0 - k * kU); }
Real kRefFactor(int m, int n) { return (4 * (m + n) + 16) * kUL; }

struct V3 {
  Real x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
V3 operator*(Real s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
Real dotL(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
V3 crossL(V3 a, V3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 absL(V3 a) { return {std::fabs(a.x), std::fabs(a.y), std::fabs(a.z)}; }
// Bound on |a x b| componentwise from bounds |a| <= A, |b| <= B.
V3 crossBound(V3 a, V3 b) {
  return {a.y * b.z + a.z * b.y, a.z * b.x + a.x * b.z, a.x * b.y + a.y * b.x};
}
V3 toL(Vec3 v) { return {v.x, v.y, v.z}; }
Real normL(V3 a) { return std::sqrt(dotL(a, a)); }

Real binomialL(int n, int k) {
  if (k < 0 || k > n) return 0;
  Real c = 1;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return c;
}

Real powInt(Real x, int k) {
  Real r = 1;
  for (; k > 0; --k) r *= x;
  return r;
}

Real falling(int n, int d) {
  Real f = 1;
  for (int i = 0; i < d; ++i) f *= n - i;
  return f;
}

Real basisL(int n, int i, Real t) {
  if (i < 0 || i > n) return 0;
  return binomialL(n, i) * powInt(1 - t, n - i) * powInt(t, i);
}

// d^d/dt^d of C(n,i) t^i (1 - t)^(n-i) by Leibniz' rule; `absolute` drops the signs (a bound
// on the magnitudes summed, for the reference's own error).
Real basisDerivativeL(int n, int i, int d, Real t, bool absolute = false) {
  Real s = 0;
  for (int a = 0; a <= d; ++a) {
    const int b = d - a;
    if (a > i || b > n - i) continue;
    Real term = binomialL(d, a) * falling(i, a) * powInt(t, i - a) * falling(n - i, b) *
                powInt(1 - t, n - i - b);
    if (!absolute && b % 2 == 1) term = -term;
    s += term;
  }
  return binomialL(n, i) * s;
}

// Reference partial derivative of order (a, b) and the magnitude sum for its own error.
std::pair<V3, V3> referencePartial(const BezierPatch& p, Real u, Real v, int a, int b) {
  std::vector<Real> bu(p.degreeU + 1), buAbs(p.degreeU + 1), bv(p.degreeV + 1),
      bvAbs(p.degreeV + 1);
  for (int j = 0; j <= p.degreeU; ++j) {
    bu[j] = basisDerivativeL(p.degreeU, j, a, u);
    buAbs[j] = basisDerivativeL(p.degreeU, j, a, u, true);
  }
  for (int k = 0; k <= p.degreeV; ++k) {
    bv[k] = basisDerivativeL(p.degreeV, k, b, v);
    bvAbs[k] = basisDerivativeL(p.degreeV, k, b, v, true);
  }
  V3 s, mag;
  for (int j = 0; j <= p.degreeU; ++j) {
    for (int k = 0; k <= p.degreeV; ++k) {
      s = s + (bu[j] * bv[k]) * toL(p.at(j, k));
      mag = mag + (buAbs[j] * bvAbs[k]) * absL(toL(p.at(j, k)));
    }
  }
  return {s, mag};
}

// F sum_jk A_jk b_j^{m-a}(u) b_k^{n-b}(v): the scale of the library's error for order (a, b)
// (see the file comment), componentwise.
V3 derivativeScale(const BezierPatch& p, Real u, Real v, int a, int b) {
  const int m = p.degreeU, n = p.degreeV;
  const auto P = [&](int j, int k) { return toL(p.at(j, k)); };
  const auto du = [&](int j, int k) { return absL(P(j + 1, k) - P(j, k)); };
  const auto dv = [&](int j, int k) { return absL(P(j, k + 1) - P(j, k)); };
  std::vector<Real> bu(m - a + 1), bv(n - b + 1);
  for (int j = 0; j <= m - a; ++j) bu[j] = basisL(m - a, j, u);
  for (int k = 0; k <= n - b; ++k) bv[k] = basisL(n - b, k, v);
  V3 s;
  for (int j = 0; j <= m - a; ++j) {
    for (int k = 0; k <= n - b; ++k) {
      V3 A;
      if (a == 0 && b == 0) A = absL(P(j, k));
      if (a == 1 && b == 0) A = du(j, k);
      if (a == 0 && b == 1) A = dv(j, k);
      if (a == 2 && b == 0) A = du(j + 1, k) + du(j, k);
      if (a == 0 && b == 2) A = dv(j, k + 1) + dv(j, k);
      if (a == 1 && b == 1) A = dv(j + 1, k) + dv(j, k);
      s = s + (bu[j] * bv[k]) * A;
    }
  }
  return falling(m, a) * falling(n, b) * s;
}

double randomUnit(std::mt19937_64& rng) {
  return std::uniform_real_distribution<double>(0.0, 1.0)(rng);
}

// A graph patch as in the paper's tests: control points over a 3 x 3 grid (jittered when
// `jitter`), heights in [-amplitude, amplitude].
BezierPatch graphPatch(std::mt19937_64& rng, int m, int n, double amplitude, bool jitter) {
  std::uniform_real_distribution<double> height(-amplitude, amplitude);
  std::uniform_real_distribution<double> shake(-0.1, 0.1);
  BezierPatch p{m, n, {}};
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k <= n; ++k) {
      const double x = 3.0 * j / m + (jitter ? shake(rng) : 0.0);
      const double y = 3.0 * k / n + (jitter ? shake(rng) : 0.0);
      p.control.push_back({x, y, height(rng)});
    }
  }
  return p;
}

BezierPatch randomSpacePatch(std::mt19937_64& rng, int m, int n) {
  std::uniform_real_distribution<double> coordinate(-2.0, 2.0);
  BezierPatch p{m, n, {}};
  for (int i = 0; i < (m + 1) * (n + 1); ++i) {
    p.control.push_back({coordinate(rng), coordinate(rng), coordinate(rng)});
  }
  return p;
}

::testing::AssertionResult within(Vec3 got, V3 want, V3 tolerance) {
  const Real ex = std::fabs(got.x - want.x), ey = std::fabs(got.y - want.y),
             ez = std::fabs(got.z - want.z);
  if (ex <= tolerance.x && ey <= tolerance.y && ez <= tolerance.z)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "errors (" << static_cast<double>(ex) << ", " << static_cast<double>(ey) << ", "
         << static_cast<double>(ez) << ") exceed (" << static_cast<double>(tolerance.x) << ", "
         << static_cast<double>(tolerance.y) << ", " << static_cast<double>(tolerance.z) << ")";
}

// ---------------------------------------------------------------------------------------
// Points and derivatives
// ---------------------------------------------------------------------------------------

TEST(BezierEvaluate, PointAndDerivativesMatchExplicitSums) {
  std::mt19937_64 rng(42);
  constexpr std::array<std::pair<int, int>, 6> kOrders = {
      {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}}};
  int checks = 0;
  // Every bidegree up to (5, 5), some higher ones, and past the one-pass derivatives' stack
  // buffers (degree 20 on the stack, 21 and up on the heap).
  std::vector<std::pair<int, int>> bidegrees;
  for (int m = 1; m <= 5; ++m) {
    for (int n = 1; n <= 5; ++n) bidegrees.emplace_back(m, n);
  }
  for (const auto& large : {std::pair{15, 15}, std::pair{16, 3}, std::pair{2, 16}, std::pair{17, 16},
                            std::pair{20, 20}, std::pair{21, 3}, std::pair{2, 22}}) {
    bidegrees.push_back(large);
  }
  for (const auto& [m, n] : bidegrees) {
    {
      const int patches = (m == 3 && n == 3) ? 200 : (m > 5 || n > 5 ? 4 : 20);
      for (int trial = 0; trial < patches; ++trial) {
        const BezierPatch p =
            trial % 2 == 0 ? graphPatch(rng, m, n, 1.0, true) : randomSpacePatch(rng, m, n);
        const std::array<Bernstein2, 3> xyz = scallop::coordinatePolynomials(p);
        for (int k = 0; k < 8; ++k) {
          const double u = k == 0 ? 0.0 : (k == 1 ? 1.0 : randomUnit(rng));
          const double v = k == 0 ? 1.0 : (k == 1 ? 0.0 : randomUnit(rng));
          for (const auto& [a, b] : kOrders) {
            Vec3 got;
            if (a == 0 && b == 0) got = scallop::point(p, u, v);
            if (a == 1 && b == 0) got = scallop::derivativeU(p, u, v);
            if (a == 0 && b == 1) got = scallop::derivativeV(p, u, v);
            if (a + b == 2) got = scallop::secondDerivative(p, u, v, a, b);
            const auto [want, magnitude] = referencePartial(p, u, v, a, b);
            const V3 scale = derivativeScale(p, u, v, a, b);
            const V3 tolerance = gamma(3 * (m + n) + 4) * scale + kRefFactor(m, n) * magnitude;
            ASSERT_TRUE(within(got, want, tolerance))
                << "bidegree (" << m << ", " << n << "), order (" << a << ", " << b << ")";
            ++checks;
            // The one-pass basis derivatives, to the same bound.
            if (a + b >= 1) {
              const scallop::PatchDerivatives d = scallop::derivativesToSecondOrder(p, u, v);
              const Vec3 onePass = a == 1 && b == 0   ? d.u
                                   : a == 0 && b == 1 ? d.v
                                   : a == 2           ? d.uu
                                   : a == 1           ? d.uv
                                                      : d.vv;
              // Its sums weigh the control points themselves (not their differences) by basis
              // derivatives whose absolute values add up to at most 2^a m^a 2^b n^b.
              V3 largest;
              for (const Vec3& c : p.control) {
                const V3 q = absL(toL(c));
                largest = {std::max(largest.x, q.x), std::max(largest.y, q.y), std::max(largest.z, q.z)};
              }
              const V3 onePassTolerance =
                  (gamma(3 * (m + n) + 8) * powInt(2.0L * m, a) * powInt(2.0L * n, b)) * largest +
                  kRefFactor(m, n) * magnitude;
              ASSERT_TRUE(within(onePass, want, onePassTolerance))
                  << "one pass, bidegree (" << m << ", " << n << "), order (" << a << ", " << b << ")";
              ++checks;
            }
          }
          // The point from the one pass's basis sums: the header's bound for them,
          // gamma(4(m + n) + 2) sum |p_jk| b_j b_k (point() is de Casteljau's).
          {
            Vec3 value;
            (void)scallop::derivativesToSecondOrder(p, u, v, value);
            const auto [want, magnitude] = referencePartial(p, u, v, 0, 0);
            const V3 tolerance = gamma(4 * (m + n) + 2) * derivativeScale(p, u, v, 0, 0) + kRefFactor(m, n) * magnitude;
            ASSERT_TRUE(within(value, want, tolerance)) << "one-pass value, bidegree (" << m << ", " << n << ")";
            ++checks;
          }
          // The coordinate polynomials evaluate by the same de Casteljau steps: bit for bit.
          const Vec3 at = scallop::point(p, u, v);
          ASSERT_EQ(evaluate(xyz[0], u, v), at.x);
          ASSERT_EQ(evaluate(xyz[1], u, v), at.y);
          ASSERT_EQ(evaluate(xyz[2], u, v), at.z);
        }
        // Corners are control points, exactly.
        ASSERT_EQ(scallop::point(p, 0.0, 0.0), p.at(0, 0));
        ASSERT_EQ(scallop::point(p, 1.0, 1.0), p.at(m, n));
        ASSERT_EQ(scallop::point(p, 1.0, 0.0), p.at(m, 0));
      }
    }
  }
  EXPECT_GT(checks, 30000);
}

// ---------------------------------------------------------------------------------------
// Normals
// ---------------------------------------------------------------------------------------

// The reference derivatives r_u, r_v with bounds |r_u| <= Ru, |r_v| <= Rv (absolute
// derivative polynomials: m sum |first differences| b b, componentwise).
struct FirstOrder {
  V3 ru, rv, ruBound, rvBound, ruMagnitude, rvMagnitude;
};

FirstOrder firstOrder(const BezierPatch& p, Real u, Real v) {
  FirstOrder f;
  std::tie(f.ru, f.ruMagnitude) = referencePartial(p, u, v, 1, 0);
  std::tie(f.rv, f.rvMagnitude) = referencePartial(p, u, v, 0, 1);
  f.ruBound = derivativeScale(p, u, v, 1, 0);
  f.rvBound = derivativeScale(p, u, v, 0, 1);
  return f;
}

// normalPolynomials: r_u, r_v coefficients round twice each (difference, product by the
// degree); a bivariate product of bidegrees (m - 1, n) and (m, n - 1) adds
// gamma(m n + 9) (bernstein.hpp), the difference of two products one rounding, and the
// evaluation of bidegree (2m - 1, 2n - 1) gamma(3(2m + 2n - 2)): all relative to the products
// of the absolute derivative polynomials.
int normalSteps(int m, int n) { return 2 + 2 + (m * n + 9) + 1 + 3 * (2 * m + 2 * n - 2); }

TEST(BezierNormal, NormalPolynomialsMatchCrossProduct) {
  std::mt19937_64 rng(42);
  for (int m = 1; m <= 5; ++m) {
    for (int n = 1; n <= 5; ++n) {
      for (int trial = 0; trial < 12; ++trial) {
        const BezierPatch p =
            trial % 2 == 0 ? graphPatch(rng, m, n, 1.0, true) : randomSpacePatch(rng, m, n);
        const std::array<Bernstein2, 3> normal = scallop::normalPolynomials(p);
        for (const Bernstein2& c : normal) {
          ASSERT_EQ(c.degreeU, 2 * m - 1);
          ASSERT_EQ(c.degreeV, 2 * n - 1);
        }
        for (int k = 0; k < 10; ++k) {
          const double u = randomUnit(rng);
          const double v = randomUnit(rng);
          const FirstOrder f = firstOrder(p, u, v);
          const V3 want = crossL(f.ru, f.rv);
          // Library: gamma(normalSteps) times |r_u| x |r_v| bounds; reference: the derivative
          // errors kRefFactor * magnitude, crossed with the other factor, plus 3 uL.
          const V3 bound = crossBound(f.ruBound, f.rvBound);
          const Real rho = kRefFactor(m, n);
          const V3 reference = rho * (crossBound(f.ruMagnitude, absL(f.rv)) +
                                      crossBound(absL(f.ru), f.rvMagnitude)) +
                               3 * kUL * crossBound(absL(f.ru), absL(f.rv));
          const V3 tolerance = gamma(normalSteps(m, n)) * bound + reference;
          const Vec3 got{evaluate(normal[0], u, v), evaluate(normal[1], u, v),
                         evaluate(normal[2], u, v)};
          ASSERT_TRUE(within(got, want, tolerance))
              << "normal, bidegree (" << m << ", " << n << ")";
          // normalVector is r_u x r_v of the evaluated derivatives, exactly.
          ASSERT_EQ(scallop::normalVector(p, u, v),
                    cross(scallop::derivativeU(p, u, v), scallop::derivativeV(p, u, v)));
        }
      }
    }
  }
}

TEST(BezierNormal, UnitNormalAndNormalLengthSquared) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 400; ++trial) {
    const int m = 1 + trial % 4, n = 1 + (trial / 4) % 4;
    const BezierPatch p = graphPatch(rng, m, n, 0.3, false);
    const Bernstein2 lengthSquared = scallop::normalLengthSquared(p);
    ASSERT_EQ(lengthSquared.degreeU, 4 * m - 2);
    ASSERT_EQ(lengthSquared.degreeV, 4 * n - 2);
    // Grid-aligned graph patch with small heights: N_z = 9 exactly and |N_x|, |N_y| <= 2.7,
    // so every coefficient of |N|^2 is positive: the regularity proof goes through.
    ASSERT_FALSE(scallop::mayVanish(lengthSquared));
    for (int k = 0; k < 10; ++k) {
      const double u = randomUnit(rng);
      const double v = randomUnit(rng);
      const FirstOrder f = firstOrder(p, u, v);
      const V3 N = crossL(f.ru, f.rv);
      const Real length = normL(N);
      const Vec3 n1 = scallop::unitNormal(p, u, v);
      // |n| = 1 up to the rounding of a normalisation (sqrt, division, three squares): 4u.
      ASSERT_NEAR(norm(n1), 1.0, 4 * kU);
      // Direction: the computed N is within e = gamma(3(m+n)+4) |Ru x Rv| + 3u |...| of the
      // reference (derivatives, then the cross product), so n within 2e / |N| plus 4u.
      const V3 bound = crossBound(f.ruBound, f.rvBound);
      const Real e = (gamma(3 * (m + n) + 4) * 2 + 3 * kU + kRefFactor(m, n)) * normL(bound);
      const V3 want = (1 / length) * N;
      ASSERT_LE(normL(toL(n1) - want), 2 * e / length + 4 * kU);
      // |N|^2 = sum N_c^2: each N_c's coefficients carry normalSteps without the evaluation
      // (twice, squared), the products gamma(4mn + 9), two sums, and the evaluation of
      // bidegree (4m - 2, 4n - 2); all relative to sum Nbar_c^2. Reference: N within
      // dN = rho (Ru_mag x |Rv| + |Ru| x Rv_mag) + 3 uL |Ru| x |Rv|, so |N|^2 within
      // 2 |N|.dN plus 3 uL |N|^2.
      const int steps = 2 * (normalSteps(m, n) - 3 * (2 * m + 2 * n - 2)) + (4 * m * n + 9) + 2 +
                        3 * (4 * m + 4 * n - 4);
      const V3 dN = kRefFactor(m, n) * (crossBound(f.ruMagnitude, absL(f.rv)) +
                                        crossBound(absL(f.ru), f.rvMagnitude)) +
                    3 * kUL * crossBound(absL(f.ru), absL(f.rv));
      ASSERT_LE(std::fabs(evaluate(lengthSquared, u, v) - dotL(N, N)),
                gamma(steps) * dotL(bound, bound) + 2 * dotL(absL(N), dN) + 3 * kUL * dotL(N, N));
    }
  }
}

TEST(BezierNormal, DegeneratePatchesThrow) {
  // All control points on one line: r_u and r_v are parallel everywhere.
  BezierPatch line{3, 3, {}};
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) {
      const double s = 0.1 * (j + 2 * k);
      line.control.push_back({s, 2 * s, 3 * s});
    }
  }
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 200; ++trial) {
    EXPECT_THROW(scallop::unitNormal(line, randomUnit(rng), randomUnit(rng)), scallop::Error);
  }
  try {
    scallop::unitNormal(line, 0.25, 0.75);
    FAIL() << "no exception";
  } catch (const scallop::Error& error) {
    EXPECT_NE(std::string(error.what()).find("(u, v) = (0.25, 0.75)"), std::string::npos)
        << error.what();
  }
  // A collapsed row (p_0k all equal, a triangular patch): r_v = 0 along u = 0 only, where
  // unitNormal gives the limit from inside (below).
  BezierPatch apex = graphPatch(rng, 3, 3, 0.5, false);
  for (int k = 0; k <= 3; ++k) apex.control[k] = {0.0, 1.5, 0.0};
  for (int trial = 0; trial < 100; ++trial) {
    const double v = randomUnit(rng);
    EXPECT_NO_THROW(scallop::unitNormal(apex, 0.0, v));
    EXPECT_NO_THROW(scallop::unitNormal(apex, 0.5 + 0.5 * randomUnit(rng), v));
  }
  const Bernstein2 lengthSquared = scallop::normalLengthSquared(apex);
  EXPECT_TRUE(scallop::mayVanish(lengthSquared));
  // Its u = 0 row is exactly zero (products of row-0 coefficients only, and r_v's vanish).
  EXPECT_TRUE(scallop::isZero(scallop::isoU(lengthSquared, 0.0)));
}

// The normal on a collapsed edge is the limit of the normals from inside: against
// unitNormal at u = 1e-7 (where r_u x r_v is small but well above rounding), on random patches
// with a collapsed row at u = 0 or u = 1 or a collapsed column, and on a cone's apex, where
// the limits differ from ray to ray.
TEST(BezierNormal, CollapsedEdgesTakeTheLimitFromInside) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    BezierPatch p = graphPatch(rng, 2 + trial % 3, 2 + (trial / 3) % 3, 0.5, false);
    const int side = trial % 4;  // 0: u = 0, 1: u = 1, 2: v = 0, 3: v = 1
    const Vec3 corner = side < 2 ? p.at(side == 0 ? 0 : p.degreeU, 1) : p.at(1, side == 2 ? 0 : p.degreeV);
    for (int j = 0; j <= p.degreeU; ++j) {
      for (int k = 0; k <= p.degreeV; ++k) {
        const bool onEdge = side == 0 ? j == 0 : side == 1 ? j == p.degreeU : side == 2 ? k == 0 : k == p.degreeV;
        if (onEdge) p.control[static_cast<std::size_t>(j * (p.degreeV + 1) + k)] = corner;
      }
    }
    const scallop::NormalDirection direction = scallop::normalDirectionPolynomials(p);
    EXPECT_TRUE(direction.powers.any()) << trial;
    for (int i = 0; i < 8; ++i) {
      const double t = 0.05 + 0.9 * randomUnit(rng);
      const double e = 1e-7;
      const double u = side == 0 ? 0.0 : side == 1 ? 1.0 : t, v = side == 2 ? 0.0 : side == 3 ? 1.0 : t;
      const double ui = side == 0 ? e : side == 1 ? 1.0 - e : t, vi = side == 2 ? e : side == 3 ? 1.0 - e : t;
      Vec3 limit, inside;
      try {
        limit = scallop::unitNormal(p, u, v);
        inside = scallop::unitNormal(p, ui, vi);
      } catch (const scallop::Error&) {
        continue;  // a random net can also be singular elsewhere on the edge (q = 0 there)
      }
      EXPECT_LT(scallop::norm(limit - inside), 1e-5) << "trial " << trial << " t " << t;
    }
  }
  // A cone over a quarter circle (rational-free: the circle's cubic approximation), apex at
  // the origin: along each ray v the normal is constant, so the limit at the apex is that
  // ray's normal and varies with v.
  BezierPatch cone{3, 3, {}};
  const double kappa = 0.5522847498;
  const Vec3 ring[4] = {{1, 0, -1}, {1, kappa, -1}, {kappa, 1, -1}, {0, 1, -1}};
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) cone.control.push_back((j / 3.0) * ring[k]);
  }
  for (double v : {0.0, 0.2, 0.5, 0.9, 1.0}) {
    const Vec3 apexNormal = scallop::unitNormal(cone, 0.0, v);
    const Vec3 rayNormal = scallop::unitNormal(cone, 0.6, v);
    EXPECT_LT(scallop::norm(apexNormal - rayNormal), 1e-12) << v;
  }
  EXPECT_GT(scallop::norm(scallop::unitNormal(cone, 0.0, 0.0) - scallop::unitNormal(cone, 0.0, 1.0)), 0.5);
}

// ---------------------------------------------------------------------------------------
// Gaussian curvature numerator
// ---------------------------------------------------------------------------------------

// Rounding steps of gaussianCurvatureNumerator relative to its absolute bound T (below), from
// the bernstein.hpp contract: derivative polynomials 2 per differentiation; N as in
// normalSteps without the evaluation (e_N); r_xx . N adds the two inputs' errors, three
// products (gamma(K + 9), K the product of (min degree + 1)s) and two sums; the final products
// (3m - 2)(3n - 2) + 9 and (3m - 1)(3n - 1) + 9; one subtraction; the evaluation of bidegree
// (6m - 4, 6n - 4).
int numeratorSteps(int m, int n) {
  const int eN = 2 + 2 + (m * n + 9) + 1;
  const int eL = 4 + eN + (m - 1) * (n + 1) + 9 + 2;
  const int eM = 4 + eN + m * n + 9 + 2;
  const int eV = 4 + eN + (m + 1) * (n - 1) + 9 + 2;
  const int first = eL + eV + (3 * m - 2) * (3 * n - 2) + 9;
  const int second = 2 * eM + (3 * m - 1) * (3 * n - 1) + 9;
  return std::max(first, second) + 1 + 3 * (6 * m + 6 * n - 8);
}

struct CurvatureReference {
  Real numerator = 0;  // K |N|^4 from the fundamental forms
  Real gaussian = 0;   // K
  Real bound = 0;      // T = (Auu.Nb)(Avv.Nb) + (Auv.Nb)^2 with absolute bounds
  Real referenceError = 0;
};

CurvatureReference curvature(const BezierPatch& p, Real u, Real v) {
  const int m = p.degreeU, n = p.degreeV;
  const FirstOrder f = firstOrder(p, u, v);
  const auto [ruu, muu] = referencePartial(p, u, v, 2, 0);
  const auto [ruv, muv] = referencePartial(p, u, v, 1, 1);
  const auto [rvv, mvv] = referencePartial(p, u, v, 0, 2);
  const V3 N = crossL(f.ru, f.rv);
  const V3 unit = (1 / normL(N)) * N;
  const Real E = dotL(f.ru, f.ru), F = dotL(f.ru, f.rv), G = dotL(f.rv, f.rv);
  const Real L = dotL(ruu, unit), M = dotL(ruv, unit), NN = dotL(rvv, unit);
  CurvatureReference c;
  c.gaussian = (L * NN - M * M) / (E * G - F * F);
  const Real area = E * G - F * F;  // = |N|^2 (Lagrange's identity)
  c.numerator = c.gaussian * area * area;
  const V3 nb = crossBound(f.ruBound, f.rvBound);
  c.bound = dotL(derivativeScale(p, u, v, 2, 0), nb) * dotL(derivativeScale(p, u, v, 0, 2), nb) +
            dotL(derivativeScale(p, u, v, 1, 1), nb) * dotL(derivativeScale(p, u, v, 1, 1), nb);
  // The reference: every derivative within kRefFactor * magnitude; the numerator is of degree
  // six in them (two in r_u, r_v through N twice, one second derivative per factor), so
  // first-order error <= 6 kRefFactor T_mag, plus some 40 uL for the fundamental forms,
  // the normalisation and K's division and product.
  const V3 nm = crossBound(f.ruMagnitude + absL(f.ru), f.rvMagnitude + absL(f.rv));
  const Real tMagnitude = dotL(muu + absL(ruu), nm) * dotL(mvv + absL(rvv), nm) +
                          dotL(muv + absL(ruv), nm) * dotL(muv + absL(ruv), nm);
  c.referenceError = (6 * kRefFactor(m, n) + 40 * kUL) * tMagnitude;
  return c;
}

TEST(BezierCurvature, NumeratorMatchesClassicalGaussianCurvature) {
  std::mt19937_64 rng(42);
  int signChecks = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int m = trial < 200 ? 3 : 2 + trial % 3;
    const int n = trial < 200 ? 3 : 2 + (trial / 3) % 3;
    const BezierPatch p =
        trial % 3 == 2 ? randomSpacePatch(rng, m, n) : graphPatch(rng, m, n, 1.0, true);
    const Bernstein2 numerator = scallop::gaussianCurvatureNumerator(p);
    ASSERT_EQ(numerator.degreeU, 6 * m - 4);
    ASSERT_EQ(numerator.degreeV, 6 * n - 4);
    for (int k = 0; k < 12; ++k) {
      const double u = randomUnit(rng);
      const double v = randomUnit(rng);
      const CurvatureReference c = curvature(p, u, v);
      const Real tolerance = gamma(numeratorSteps(m, n)) * c.bound + c.referenceError;
      const double got = evaluate(numerator, u, v);
      ASSERT_LE(std::fabs(got - c.numerator), tolerance) << "trial " << trial;
      // The pointwise formula from the one-pass derivatives agrees as closely.
      ASSERT_LE(std::fabs(scallop::gaussianCurvatureNumeratorAt(p, u, v) - c.numerator), tolerance)
          << "pointwise, trial " << trial;
      if (std::fabs(c.numerator) > tolerance) {
        ASSERT_EQ(got > 0, c.gaussian > 0) << "sign of K, trial " << trial;
        ++signChecks;
      }
    }
  }
  EXPECT_GT(signChecks, 3000);
}

TEST(BezierCurvature, ParabolicLinesAreInsideTheSquaresThatMayVanish) {
  // The quadtree test of the paper's section 3.1: on an 8 x 8 grid of sub-squares, a square
  // whose restricted numerator has coefficients of one strict sign holds no parabolic point,
  // so the reference K keeps that sign at every sample inside it (where it is above the
  // tolerance); a square where the reference K changes sign must report mayVanish.
  std::mt19937_64 rng(42);
  int squaresWithParabolicPoints = 0;
  int provedSquares = 0;
  constexpr int kSquares = 8;
  constexpr int kSamples = 4;  // sample spacing: 1 / (kSquares kSamples); squares share edges
  constexpr int kGrid = kSquares * kSamples + 1;
  for (int trial = 0; trial < 24; ++trial) {
    const BezierPatch p = graphPatch(rng, 3, 3, 1.0, true);
    const Bernstein2 numerator = scallop::gaussianCurvatureNumerator(p);
    // Reference sign on the sample grid: +1, -1, or 0 within the tolerance.
    std::vector<int> sign(kGrid * kGrid);
    for (int i = 0; i < kGrid; ++i) {
      for (int j = 0; j < kGrid; ++j) {
        const double u = static_cast<double>(i) / (kGrid - 1),
                     v = static_cast<double>(j) / (kGrid - 1);
        const CurvatureReference c = curvature(p, u, v);
        const Real tolerance = gamma(numeratorSteps(3, 3)) * c.bound + c.referenceError;
        sign[i * kGrid + j] = c.numerator > tolerance ? 1 : (c.numerator < -tolerance ? -1 : 0);
      }
    }
    for (int a = 0; a < kSquares; ++a) {
      for (int b = 0; b < kSquares; ++b) {
        const double u0 = static_cast<double>(a) / kSquares, v0 = static_cast<double>(b) / kSquares;
        const double side = 1.0 / kSquares;
        const Bernstein2 square = scallop::restrictTo(numerator, u0, u0 + side, v0, v0 + side);
        const bool may = scallop::mayVanish(square);
        const int proved = scallop::bounds(square).lo > 0 ? 1 : -1;
        bool positive = false, negative = false;
        for (int i = a * kSamples; i <= (a + 1) * kSamples; ++i) {
          for (int j = b * kSamples; j <= (b + 1) * kSamples; ++j) {
            const int s = sign[i * kGrid + j];
            positive = positive || s > 0;
            negative = negative || s < 0;
            if (!may && s != 0) {
              ASSERT_EQ(s, proved) << "trial " << trial;
            }
          }
        }
        if (positive && negative) {
          ASSERT_TRUE(may) << "a parabolic line crosses a square proved free of them";
          ++squaresWithParabolicPoints;
        }
        provedSquares += may ? 0 : 1;
      }
    }
  }
  std::printf("[          ] %d squares crossed by parabolic lines, %d proved free of them\n",
              squaresWithParabolicPoints, provedSquares);
  EXPECT_GT(squaresWithParabolicPoints, 50);
  EXPECT_GT(provedSquares, 300);
}

TEST(BezierCurvature, ClosedFormSurfaces) {
  // x = 3u, y = 3v throughout (control x = j, y = k: linear precision).
  const auto grid = [](auto height) {
    BezierPatch p{3, 3, {}};
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) p.control.push_back({double(j), double(k), height(j, k)});
    }
    return p;
  };
  // Plane z = 0: the x and y components of N are products with zero polynomials, and
  // r_uu . N = x_uu 0 + y_uu 0 + 0 N_z: every coefficient is exactly 0.
  const Bernstein2 plane = scallop::gaussianCurvatureNumerator(grid([](int, int) { return 0.0; }));
  for (double c : plane.coefficients) ASSERT_EQ(c, 0.0);
  // Parabolic cylinder z = x^2 = 9u^2 (u^2 = {0, 0, 1/3, 1} in cubic Bernstein form): r_vv = 0
  // and r_uv = 0 exactly, so K = 0 identically and the numerator is exactly 0.
  const double cylinderZ[4] = {0.0, 0.0, 3.0, 9.0};
  const Bernstein2 cylinder =
      scallop::gaussianCurvatureNumerator(grid([&](int j, int) { return cylinderZ[j]; }));
  for (double c : cylinder.coefficients) ASSERT_EQ(c, 0.0);
  // Saddle z = xy = 9uv (control z = jk): r_u = (3, 0, 9v), r_v = (0, 3, 9u),
  // N = (-27v, -27u, 9), r_uu = r_vv = 0, r_uv = (0, 0, 9): numerator = -(81)^2 = -6561
  // everywhere. N_z's coefficients are 9 within gamma(e_N) (as in numeratorSteps); r_uv . N
  // is the product of r_uv's z (coefficients 9, exact) with N_z, bidegrees (2, 2) x (5, 5):
  // gamma(e_N + 3 * 3 + 9); its square, (7, 7) x (7, 7), adds gamma(8 * 8 + 9); r_uu . N and
  // r_vv . N are exactly zero, so the final subtraction is exact.
  const Bernstein2 saddle =
      scallop::gaussianCurvatureNumerator(grid([](int j, int k) { return double(j * k); }));
  const int eN = 2 + 2 + (3 * 3 + 9) + 1;
  const int saddleSteps = 2 * (eN + 3 * 3 + 9) + 8 * 8 + 9;
  for (double c : saddle.coefficients)
    ASSERT_LE(std::fabs(c + 6561.0), 6561.0 * gamma(saddleSteps));
  EXPECT_FALSE(scallop::mayVanish(saddle));
  EXPECT_LT(scallop::bounds(saddle).hi, 0.0);
  // Elliptic cap z = -(x^2 + y^2) / 9 = -(u^2 + v^2): K > 0 everywhere, every coefficient
  // positive (a proof of no parabolic point), and the values match the reference.
  const double square[4] = {0.0, 0.0, 1.0 / 3.0, 1.0};
  const BezierPatch capPatch = grid([&](int j, int k) { return -(square[j] + square[k]); });
  const Bernstein2 cap = scallop::gaussianCurvatureNumerator(capPatch);
  EXPECT_FALSE(scallop::mayVanish(cap));
  EXPECT_GT(scallop::bounds(cap).lo, 0.0);
  // Tilted plane z = 2x + 3y over an integer grid with integer jitter: exactly coplanar
  // control points, so the ideal numerator vanishes; the computed one is within the
  // rounding bound.
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> shake(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    BezierPatch tilted{3, 3, {}};
    for (int j = 0; j <= 3; ++j) {
      for (int k = 0; k <= 3; ++k) {
        const double x = 4 * j + shake(rng), y = 4 * k + shake(rng);
        tilted.control.push_back({x, y, 2 * x + 3 * y});
      }
    }
    const Bernstein2 numerator = scallop::gaussianCurvatureNumerator(tilted);
    for (int k = 0; k < 10; ++k) {
      const double u = randomUnit(rng), v = randomUnit(rng);
      const CurvatureReference c = curvature(tilted, u, v);
      ASSERT_LE(std::fabs(evaluate(numerator, u, v)),
                gamma(numeratorSteps(3, 3)) * c.bound + c.referenceError);
    }
  }
}

TEST(BezierCurvature, DegreesOfThePolynomialViews) {
  std::mt19937_64 rng(42);
  for (const auto& [m, n] :
       std::vector<std::pair<int, int>>{{1, 1}, {1, 3}, {3, 1}, {2, 5}, {3, 3}, {4, 2}}) {
    const BezierPatch p = randomSpacePatch(rng, m, n);
    const std::array<Bernstein2, 3> xyz = scallop::coordinatePolynomials(p);
    EXPECT_EQ(xyz[0].degreeU, m);
    EXPECT_EQ(xyz[2].degreeV, n);
    const Bernstein2 numerator = scallop::gaussianCurvatureNumerator(p);
    EXPECT_EQ(numerator.degreeU, 6 * m - 4);
    EXPECT_EQ(numerator.degreeV, 6 * n - 4);
    const Bernstein2 lengthSquared = scallop::normalLengthSquared(p);
    EXPECT_EQ(lengthSquared.degreeU, 4 * m - 2);
    EXPECT_EQ(lengthSquared.degreeV, 4 * n - 2);
    // The numerator matches the reference on low bidegrees too (r_uu or r_vv vanish for 1).
    for (int k = 0; k < 20; ++k) {
      const double u = randomUnit(rng), v = randomUnit(rng);
      const CurvatureReference c = curvature(p, u, v);
      ASSERT_LE(std::fabs(evaluate(numerator, u, v) - c.numerator),
                gamma(numeratorSteps(m, n)) * c.bound + c.referenceError)
          << m << " x " << n;
    }
  }
}

TEST(BezierCurvature, ScalingByPowersOfTwoIsExact) {
  // Every operation scales exactly by a power of two: N by 4, the numerator by 2^6.
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 20; ++trial) {
    const BezierPatch p = graphPatch(rng, 3, 3, 1.0, true);
    BezierPatch q = p;
    for (Vec3& c : q.control) c = 2.0 * c;
    const Bernstein2 a = scallop::gaussianCurvatureNumerator(p);
    const Bernstein2 b = scallop::gaussianCurvatureNumerator(q);
    for (std::size_t i = 0; i < a.coefficients.size(); ++i) {
      ASSERT_EQ(b.coefficients[i], 64.0 * a.coefficients[i]);
    }
  }
}

// True when p > 0 is proved on [0, 1]^2 by positive coefficients on the squares of a quadtree
// of at most `depth` levels.
bool provePositive(const Bernstein2& p, int depth) {
  if (scallop::bounds(p).lo > 0.0) return true;
  if (depth == 0) return false;
  const auto [left, right] = scallop::subdivideU(p, 0.5);
  for (const Bernstein2* half : {&left, &right}) {
    const auto [lower, upper] = scallop::subdivideV(*half, 0.5);
    if (!provePositive(lower, depth - 1) || !provePositive(upper, depth - 1)) return false;
  }
  return true;
}

TEST(BezierNormal, CertifiesNormalsAwayFromADirection) {
  // The recipe of bezier.hpp: A = cos^2(alpha) |N|^2 - (N . d)^2 > 0 coefficientwise (on the
  // squares of a quadtree) proves |n . d| < cos(alpha), here alpha = 60 degrees, d = x.
  // Heights in [-0.15, 0.15] over the jittered 3 x 3 grid give |z_u| <= 3 * 0.3 = 0.9 against
  // x_u >= 3 * 0.8 = 2.4 (and the same in v), so |n . x| <= 0.9 / 2.4 < 0.38 < 0.5: the proof
  // must succeed. Heights in [-0.4, 0.4] sometimes bring normals within the angle: then the proof
  // must fail, and wherever it succeeds every sampled unit normal must agree.
  std::mt19937_64 rng(42);
  const double cosAlpha = 0.5;
  const Vec3 d{1.0, 0.0, 0.0};
  const auto certificate = [&](const BezierPatch& p) {
    const std::array<Bernstein2, 3> normal = scallop::normalPolynomials(p);
    const Bernstein2 along =
        scallop::add(scallop::add(scallop::scale(normal[0], d.x), scallop::scale(normal[1], d.y)),
                     scallop::scale(normal[2], d.z));
    return scallop::subtract(scallop::scale(scallop::normalLengthSquared(p), cosAlpha * cosAlpha),
                             scallop::multiply(along, along));
  };
  for (int trial = 0; trial < 100; ++trial) {
    ASSERT_TRUE(provePositive(certificate(graphPatch(rng, 3, 3, 0.15, true)), 4)) << trial;
  }
  int proved = 0, refuted = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const BezierPatch p = graphPatch(rng, 3, 3, 0.4, true);
    const bool ok = provePositive(certificate(p), 4);
    double worst = 0.0;
    for (int i = 0; i <= 20; ++i) {
      for (int j = 0; j <= 20; ++j) {
        worst = std::max(worst, std::fabs(dot(scallop::unitNormal(p, i / 20.0, j / 20.0), d)));
      }
    }
    if (ok) {
      ASSERT_LT(worst, cosAlpha) << trial;
      ++proved;
    }
    if (worst >= cosAlpha) {
      ASSERT_FALSE(ok) << trial;
      ++refuted;
    }
  }
  std::printf("[          ] normal cones: %d proved, %d refuted by a sample, of 100\n", proved,
              refuted);
  EXPECT_GT(proved, 10);
  EXPECT_GT(refuted, 10);
  // And it must fail where a normal does come within the angle: the saddle z = xy over
  // [0, 3]^2 has N = (-27v, -27u, 9), so n . x = -27 / sqrt(27^2 + 9^2) ~ -0.95 at (0, 1).
  BezierPatch saddle{3, 3, {}};
  for (int j = 0; j <= 3; ++j) {
    for (int k = 0; k <= 3; ++k) saddle.control.push_back({double(j), double(k), double(j * k)});
  }
  const std::array<Bernstein2, 3> normal = scallop::normalPolynomials(saddle);
  const Bernstein2 a =
      scallop::subtract(scallop::scale(scallop::normalLengthSquared(saddle), cosAlpha * cosAlpha),
                        scallop::multiply(normal[0], normal[0]));
  EXPECT_TRUE(scallop::mayVanish(a));
  EXPECT_GT(std::fabs(scallop::unitNormal(saddle, 0.0, 1.0).x), cosAlpha);
}

// ---------------------------------------------------------------------------------------
// Subdivision
// ---------------------------------------------------------------------------------------

TEST(BezierSubdivide, SubPatchesReproduceTheSurface) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 300; ++trial) {
    const int m = trial < 150 ? 3 : 1 + trial % 5;
    const int n = trial < 150 ? 3 : 1 + (trial / 5) % 5;
    const BezierPatch p =
        trial % 2 == 0 ? graphPatch(rng, m, n, 1.0, true) : randomSpacePatch(rng, m, n);
    const double t = randomUnit(rng);
    const auto [left, right] = scallop::subdivideU(p, t);
    const auto [lower, upper] = scallop::subdivideV(p, t);
    // Shared boundary curves and kept boundaries are exact.
    for (int k = 0; k <= n; ++k) {
      ASSERT_EQ(left.at(m, k), right.at(0, k));
      ASSERT_EQ(left.at(0, k), p.at(0, k));
      ASSERT_EQ(right.at(m, k), p.at(m, k));
    }
    for (int j = 0; j <= m; ++j) ASSERT_EQ(lower.at(j, n), upper.at(j, 0));
    const double u0 = randomUnit(rng), u1 = randomUnit(rng), v0 = randomUnit(rng),
                 v1 = randomUnit(rng);
    const BezierPatch box = scallop::restrictTo(p, u0, u1, v0, v1);
    // Bounds on |r_u| and |r_v| over the patch, for the moved interval ends of restrictTo.
    V3 su, sv;
    for (int j = 0; j <= m; ++j) {
      for (int k = 0; k <= n; ++k) {
        if (j < m) {
          const V3 d = absL(toL(p.at(j + 1, k)) - toL(p.at(j, k)));
          su = {std::max(su.x, m * d.x), std::max(su.y, m * d.y), std::max(su.z, m * d.z)};
        }
        if (k < n) {
          const V3 d = absL(toL(p.at(j, k + 1)) - toL(p.at(j, k)));
          sv = {std::max(sv.x, n * d.x), std::max(sv.y, n * d.y), std::max(sv.z, n * d.z)};
        }
      }
    }
    for (int k = 0; k < 10; ++k) {
      const double s = randomUnit(rng), r = randomUnit(rng);
      // Subdivision along u: gamma(3m) on the control points, evaluation gamma(3(m + n));
      // restriction: gamma(6m) + gamma(6n), and interval ends moved by 3u (2|a| + |b|) each
      // way times the derivative bounds (bernstein.hpp).
      const Real ts = static_cast<Real>(t) * s;
      const Real te = t + (1 - static_cast<Real>(t)) * s;
      const Real factor = gamma(3 * std::max(m, n)) +
                          gamma(3 * (m + n)) * (1 + gamma(3 * std::max(m, n))) + kRefFactor(m, n);
      const auto check = [&](const BezierPatch& piece, double a, double b, Real x, Real y,
                             const char* what) {
        const auto [want, magnitude] = referencePartial(p, x, y, 0, 0);
        ASSERT_TRUE(within(scallop::point(piece, a, b), want, factor * magnitude)) << what;
      };
      check(left, s, r, ts, r, "left");
      check(right, s, r, te, r, "right");
      check(lower, r, s, r, ts, "lower");
      check(upper, r, s, r, te, "upper");
      const Real x = u0 + (static_cast<Real>(u1) - u0) * s;
      const Real y = v0 + (static_cast<Real>(v1) - v0) * r;
      const auto [want, magnitude] = referencePartial(p, x, y, 0, 0);
      const Real boxFactor = (gamma(6 * m) + gamma(6 * n) +
                              gamma(3 * (m + n)) * (1 + gamma(6 * (m + n))) + kRefFactor(m, n)) *
                             (1 + gamma(6 * m));
      const Real du = 3 * kU * (2 * u0 + u1), dv = 3 * kU * (2 * v0 + v1);
      ASSERT_TRUE(
          within(scallop::point(box, s, r), want, boxFactor * magnitude + du * su + dv * sv))
          << "box";
    }
  }
}

TEST(BezierErrors, InvalidPatchesAndOrdersThrow) {
  BezierPatch empty;
  EXPECT_THROW(scallop::point(empty, 0.5, 0.5), scallop::Error);
  EXPECT_THROW(scallop::point(BezierPatch{0, 3, std::vector<Vec3>(4)}, 0.5, 0.5), scallop::Error);
  EXPECT_THROW(scallop::normalPolynomials(BezierPatch{3, 3, std::vector<Vec3>(15)}),
               scallop::Error);
  EXPECT_THROW(scallop::derivativesToSecondOrder(BezierPatch{3, 3, std::vector<Vec3>(15)}, 0.5, 0.5),
               scallop::Error);
  EXPECT_THROW(scallop::gaussianCurvatureNumeratorAt(empty, 0.5, 0.5), scallop::Error);
  const BezierPatch ok{1, 1, {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 1}}};
  EXPECT_NO_THROW(scallop::secondDerivative(ok, 0.5, 0.5, 1, 1));
  EXPECT_THROW(scallop::secondDerivative(ok, 0.5, 0.5, 1, 0), scallop::Error);
  EXPECT_THROW(scallop::secondDerivative(ok, 0.5, 0.5, 3, -1), scallop::Error);
  // Bilinear: r_uu = r_vv = 0, r_uv = p_11 - p_10 - p_01 + p_00 = (0, 0, 1).
  EXPECT_EQ(scallop::secondDerivative(ok, 0.3, 0.6, 2, 0), (Vec3{0, 0, 0}));
  EXPECT_EQ(scallop::secondDerivative(ok, 0.3, 0.6, 1, 1), (Vec3{0, 0, 1}));
}

}  // namespace

// --- rational patches (the contract's Rational patches) ------------------------------------

using scallop::test::randomRationalPatch;
using scallop::test::torusPatch;

TEST(BezierRational, TorusPatchesLieOnTheTorusWithTheirCurvatureSign) {
  const double a = 3.0, b = 1.0;
  for (const bool outer : {true, false}) {
    const BezierPatch patch = torusPatch(a, b, outer);
    const Bernstein2 curvature = scallop::gaussianCurvatureNumerator(patch);
    const std::array<Bernstein2, 3> normal = scallop::normalPolynomials(patch);
    for (int i = 0; i <= 20; ++i)
      for (int k = 0; k <= 20; ++k) {
        const double u = i / 20.0, v = k / 20.0;
        const Vec3 p = scallop::point(patch, u, v);
        EXPECT_NEAR(std::pow(std::hypot(p.x, p.y) - a, 2) + p.z * p.z, b * b, 1e-13) << u << ", " << v;
        // The unit normal is the tube's: along p minus the nearest point of the core circle.
        const double rho = std::hypot(p.x, p.y);
        const Vec3 radial = Vec3{p.x - a * p.x / rho, p.y - a * p.y / rho, p.z} / b;
        const Vec3 n = scallop::unitNormal(patch, u, v);
        EXPECT_NEAR(std::abs(dot(n, radial)), 1.0, 1e-12) << u << ", " << v;
        const Vec3 q{scallop::evaluate(normal[0], u, v), scallop::evaluate(normal[1], u, v),
                     scallop::evaluate(normal[2], u, v)};
        EXPECT_NEAR(dot(q, n) / norm(q), 1.0, 1e-12) << "normal polynomial's direction at " << u << ", " << v;
        // K = cos(phi) / (b (a + b cos(phi))), cos(phi) = (rho - a) / b: its sign.
        const double cosPhi = (rho - a) / b;
        const double sign = scallop::evaluate(curvature, u, v);
        if (std::abs(cosPhi) > 1e-6) {
          EXPECT_EQ(sign > 0.0, cosPhi > 0.0) << u << ", " << v << ": " << sign;
        }
      }
  }
}

TEST(BezierRational, RandomPatchesDerivativesNormalAndCurvatureAgainstIndependentReferences) {
  std::mt19937_64 rng(20261127);
  for (int trial = 0; trial < 300; ++trial) {
    const int m = 1 + trial % 4, n = 1 + (trial / 4) % 4;
    const BezierPatch patch = randomRationalPatch(rng, m, n);
    // The reference point: the defining sums, in long double.
    const auto reference = [&](double u, double v) {
      Real x = 0, y = 0, z = 0, w = 0;
      for (int j = 0; j <= m; ++j)
        for (int k = 0; k <= n; ++k) {
          Real bj = 1, bk = 1;
          for (int i = 0; i < j; ++i) bj *= Real(m - i) / Real(i + 1);
          for (int i = 0; i < k; ++i) bk *= Real(n - i) / Real(i + 1);
          bj *= std::pow(Real(u), j) * std::pow(Real(1 - u), m - j);
          bk *= std::pow(Real(v), k) * std::pow(Real(1 - v), n - k);
          const Real c = bj * bk * patch.weight(j, k);
          x += c * patch.at(j, k).x, y += c * patch.at(j, k).y, z += c * patch.at(j, k).z, w += c;
        }
      return std::array<Real, 3>{x / w, y / w, z / w};
    };
    std::uniform_real_distribution<double> parameter(0.05, 0.95);
    const double u = parameter(rng), v = parameter(rng), h = 1e-4;
    const auto at = [&](double uu, double vv) {
      const auto r = reference(uu, vv);
      return std::array<Real, 3>{r[0], r[1], r[2]};
    };
    const Vec3 p = scallop::point(patch, u, v);
    const auto r0 = at(u, v);
    EXPECT_NEAR(p.x, double(r0[0]), 1e-13);
    EXPECT_NEAR(p.y, double(r0[1]), 1e-13);
    EXPECT_NEAR(p.z, double(r0[2]), 1e-13);
    // Central differences of the reference (error O(h^2) with a quotient's derivatives ~ 1e2).
    const auto difference = [&](int du, int dv) {
      Vec3 out;
      double c[3];
      for (int i = 0; i < 3; ++i) {
        Real value;
        if (du == 1 && dv == 0) value = (at(u + h, v)[i] - at(u - h, v)[i]) / (2 * h);
        else if (du == 0 && dv == 1) value = (at(u, v + h)[i] - at(u, v - h)[i]) / (2 * h);
        else if (du == 2) value = (at(u + h, v)[i] - 2 * at(u, v)[i] + at(u - h, v)[i]) / (h * h);
        else if (dv == 2) value = (at(u, v + h)[i] - 2 * at(u, v)[i] + at(u, v - h)[i]) / (h * h);
        else value = (at(u + h, v + h)[i] - at(u + h, v - h)[i] - at(u - h, v + h)[i] + at(u - h, v - h)[i]) / (4 * h * h);
        c[i] = double(value);
      }
      out = {c[0], c[1], c[2]};
      return out;
    };
    const scallop::PatchDerivatives d = scallop::derivativesToSecondOrder(patch, u, v);
    const auto near = [&](Vec3 a, Vec3 b, double tolerance, const char* what) {
      EXPECT_LE(norm(a - b), tolerance * (1.0 + norm(b))) << what << " trial " << trial;
    };
    near(scallop::derivativeU(patch, u, v), difference(1, 0), 1e-5, "r_u");
    near(scallop::derivativeV(patch, u, v), difference(0, 1), 1e-5, "r_v");
    near(d.u, scallop::derivativeU(patch, u, v), 1e-14, "r_u in one pass");
    near(d.uu, difference(2, 0), 1e-3, "r_uu");
    near(d.uv, difference(1, 1), 1e-3, "r_uv");
    near(d.vv, difference(0, 2), 1e-3, "r_vv");
    near(scallop::secondDerivative(patch, u, v, 1, 1), d.uv, 1e-14, "r_uv alone");
    // N's direction and K's sign from the polynomials against the derivatives at the point:
    // N = w^3 r_u x r_v and the curvature polynomial = w^10 (r_uu . n)(r_vv . n) - (r_uv . n)^2.
    const std::array<Bernstein2, 3> normal = scallop::normalPolynomials(patch);
    const double w = scallop::evaluate(scallop::homogeneousPolynomials(patch)[3], u, v);
    const Vec3 cross = scallop::cross(d.u, d.v);
    const Vec3 q{scallop::evaluate(normal[0], u, v), scallop::evaluate(normal[1], u, v),
                 scallop::evaluate(normal[2], u, v)};
    near(q, w * w * w * cross, 1e-11, "N = w^3 r_u x r_v");
    const double pointwise = scallop::gaussianCurvatureNumeratorAt(patch, u, v);
    const double polynomial = scallop::evaluate(scallop::gaussianCurvatureNumerator(patch), u, v);
    EXPECT_NEAR(polynomial, std::pow(w, 10) * pointwise, 1e-9 * (1.0 + std::abs(std::pow(w, 10) * pointwise)))
        << "trial " << trial;
    EXPECT_NEAR(scallop::evaluate(scallop::normalLengthSquared(patch), u, v), dot(q, q), 1e-11 * (1.0 + dot(q, q)));
    // A sub-patch is the patch, reparametrised.
    const BezierPatch piece = scallop::restrictTo(patch, 0.2, 0.7, 0.1, 0.9);
    ASSERT_TRUE(piece.rational());
    for (const double s : {0.0, 0.3, 1.0})
      near(scallop::point(piece, s, s), scallop::point(patch, 0.2 + 0.5 * s, 0.1 + 0.8 * s), 1e-13, "sub-patch");
  }
}

TEST(BezierRational, EqualWeightsAreThePolynomialPatch) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    BezierPatch rational = randomRationalPatch(rng, 1 + trial % 3, 1 + trial % 4);
    BezierPatch polynomial = rational;
    polynomial.weights.clear();
    rational.weights.assign(rational.weights.size(), 2.5);
    for (const double u : {0.0, 0.31, 1.0})
      for (const double v : {0.0, 0.77, 1.0}) {
        EXPECT_LE(norm(scallop::point(rational, u, v) - scallop::point(polynomial, u, v)), 1e-15);
        EXPECT_LE(norm(scallop::unitNormal(rational, u, v) - scallop::unitNormal(polynomial, u, v)), 1e-13);
        const double kr = scallop::gaussianCurvatureNumeratorAt(rational, u, v);
        const double kp = scallop::gaussianCurvatureNumeratorAt(polynomial, u, v);
        EXPECT_NEAR(kr, kp, 1e-12 * (1.0 + std::abs(kp)));
      }
  }
}

TEST(BezierRational, BadWeightsAreRefusedByIndex) {
  BezierPatch patch = torusPatch(3.0, 1.0, true);
  patch.weights.pop_back();
  EXPECT_THROW((void)scallop::point(patch, 0.5, 0.5), scallop::Error);
  for (const double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    BezierPatch weighted = torusPatch(3.0, 1.0, true);
    weighted.weights[4] = bad;
    try {
      (void)scallop::point(weighted, 0.5, 0.5);
      ADD_FAILURE() << "weight " << bad << " accepted";
    } catch (const scallop::Error& error) {
      EXPECT_NE(std::string(error.what()).find("weight 4"), std::string::npos) << error.what();
    }
  }
  EXPECT_THROW((void)scallop::coordinatePolynomials(torusPatch(3.0, 1.0, true)), scallop::Error);
}
