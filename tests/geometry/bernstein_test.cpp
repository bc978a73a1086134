// Tests for bernstein.hpp: univariate and tensor-product Bernstein polynomials and real-root
// isolation.
//
// References, all written in this file and independent of src/:
//  - explicit basis sums sum_i c_i C(n,i) (1-t)^(n-i) t^i in long double (and their
//    derivatives from d/dt b_i^n = n (b_{i-1}^{n-1} - b_i^{n-1}) with explicit basis values);
//  - power-basis Horner in long double;
//  - polynomials built from known roots, prod (t - r_i) prod ((t - a)^2 + b^2), multiplied
//    out in long double with a running bound on the construction error.
//
// Tolerances. u = 2^-53 (double), uL = long double's unit roundoff (2^-64 on x86-64),
// gamma(k) = k u / (1 - k u). Every bound below is the header's contract bound for the
// operation under test (bernstein.hpp, "Numerical behaviour"), evaluated with this file's
// own absolute polynomials Pbar(t) = sum |c_i| b_i(t), plus the reference's own error:
//  - an explicit basis sum in long double: each term is a binomial (exact below 2^64), 1 - t
//    (one rounding, raised to the power n - i: n - i roundings' worth), two powers by repeated
//    products (n - 1 roundings) and two products; the sum adds n. Below (3n + 4) uL per unit
//    of Pbar; we charge kRefFactor(n) = (4n + 8) uL;
//  - Horner in long double: 2n uL times sum |a_j| t^j (standard bound).
// Roots: the contract promises that the roots of every polynomial within one rounding of the
// given coefficients are covered. The ideal polynomial p* (exact roots) differs from its
// long double construction by at most the tracked bound err_i per coefficient; rounding to
// double is within the family. A root of multiplicity mu at r with D = |p*^(mu)(r)| / mu!
// moves by at most about (Delta(r) / D)^(1/mu) under a perturbation of size
// Delta(r) = sum err_i b_i(r) (first-order perturbation theory); we allow twice that (rho).
// A simple root refined by realRoots is off by at most (family + evaluation noise) /|p'|:
// (u + gamma(3n)) Pbar(r) / |p*'(r)|, plus rho, plus the final bracket (2 ulps); we allow
// 2 (3n + 1) u Pbar(r) / |p*'(r)| + rho + 4 u |r|.
//
// Tests (gtest suite names):
//  BernsteinEvaluate      explicit basis sums (degrees 0..25), power-basis Horner;
//  BernsteinDerivative    explicit derivative, power-basis derivative, finite differences;
//  BernsteinMultiply / Add / Elevate / Subdivide / Restrict / Bounds   pointwise identities;
//  BernsteinSignVariations, BernsteinPowerBasis, BernsteinErrors;
//  BernsteinRoots         linear (machine precision), no roots, exact roots at the ends, roots
//                         a hair inside / outside, close pairs 1e-3 .. 1e-12, double to
//                         quadruple roots (cluster width vs the noise band), (t - 1/2)^14,
//                         Wilkinson-like degrees 10..30, 2000 random mixes, coarse resolution,
//                         the zero polynomial, scaling / mirroring / determinism;
//  Bernstein2*            tensor product: evaluation, derivatives, product, sums, elevation,
//                         subdivision, restriction, bounds, mayVanish, iso-lines.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/error.hpp"

namespace {

using scallop::Bernstein1;
using scallop::Bernstein2;
using scallop::RootInterval;
using scallop::RootOptions;
using Real = long double;

constexpr double kU = std::numeric_limits<double>::epsilon() / 2;
constexpr Real kUL = std::numeric_limits<Real>::epsilon() / 2;

double gamma(int k) { return k * kU / (1.0 - k * kU); }
Real kRefFactor(int n) { return (4 * n + 8) * kUL; }

// ---------------------------------------------------------------------------------------
// Long double references
// ---------------------------------------------------------------------------------------

Real binomialL(int n, int k) {
  if (k < 0 || k > n) return 0;
  Real c = 1;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;  // C(n-k+i, i) at every step: exact
  return c;
}

Real powInt(Real x, int k) {
  Real r = 1;
  for (; k > 0; --k) r *= x;
  return r;
}

Real basisL(int n, int i, Real t) {
  if (i < 0 || i > n) return 0;
  return binomialL(n, i) * powInt(1 - t, n - i) * powInt(t, i);
}

Real explicitSum(const std::vector<double>& c, Real t) {
  const int n = static_cast<int>(c.size()) - 1;
  Real s = 0;
  for (int i = 0; i <= n; ++i) s += c[i] * basisL(n, i, t);
  return s;
}

// Pbar(t) = sum |c_i| b_i(t), the scale of every rounding error.
Real absoluteSum(const std::vector<double>& c, Real t) {
  const int n = static_cast<int>(c.size()) - 1;
  Real s = 0;
  for (int i = 0; i <= n; ++i) s += std::fabs(static_cast<Real>(c[i])) * basisL(n, i, t);
  return s;
}

// p'(t) = n sum_i c_i (b_{i-1}^{n-1}(t) - b_i^{n-1}(t)) with explicit basis values; the second
// member of the pair bounds the sum's magnitude, n sum_i |c_i| (b_{i-1}^{n-1} + b_i^{n-1}).
std::pair<Real, Real> explicitDerivative(const std::vector<double>& c, Real t) {
  const int n = static_cast<int>(c.size()) - 1;
  Real s = 0;
  Real a = 0;
  for (int i = 0; i <= n; ++i) {
    const Real b = basisL(n - 1, i - 1, t) - basisL(n - 1, i, t);
    s += c[i] * b;
    a += std::fabs(static_cast<Real>(c[i])) * (basisL(n - 1, i - 1, t) + basisL(n - 1, i, t));
  }
  return {n * s, n * a};
}

Real horner(const std::vector<Real>& a, Real t) {
  Real s = 0;
  for (std::size_t j = a.size(); j-- > 0;) s = s * t + a[j];
  return s;
}

Real hornerAbs(const std::vector<Real>& a, Real t) {
  Real s = 0;
  for (std::size_t j = a.size(); j-- > 0;) s = s * std::fabs(t) + std::fabs(a[j]);
  return s;
}

std::vector<double> randomCoefficients(std::mt19937_64& rng, int n, double lo = -1.0,
                                       double hi = 1.0) {
  std::uniform_real_distribution<double> coefficient(lo, hi);
  std::vector<double> c(n + 1);
  for (double& x : c) x = coefficient(rng);
  return c;
}

double randomUnit(std::mt19937_64& rng) {
  return std::uniform_real_distribution<double>(0.0, 1.0)(rng);
}

// Evaluation parameters: the ends, points near them, and uniform samples.
std::vector<double> sampleParameters(std::mt19937_64& rng, int count) {
  std::vector<double> t = {0.0, 1.0, 1e-300, 1e-9, 0.5, 1.0 - 1e-9};
  while (static_cast<int>(t.size()) < count) t.push_back(randomUnit(rng));
  return t;
}

Real maxAbs(const std::vector<double>& c) {
  Real m = 0;
  for (double x : c) m = std::max(m, std::fabs(static_cast<Real>(x)));
  return m;
}

// ---------------------------------------------------------------------------------------
// Univariate: evaluation, derivative, product, sum, elevation, subdivision, restriction
// ---------------------------------------------------------------------------------------

TEST(BernsteinEvaluate, MatchesExplicitBasisSum) {
  std::mt19937_64 rng(42);
  int checks = 0;
  for (int n = 0; n <= 25; ++n) {
    for (int trial = 0; trial < 60; ++trial) {
      const Bernstein1 p{randomCoefficients(rng, n)};
      for (double t : sampleParameters(rng, 16)) {
        const Real reference = explicitSum(p.coefficients, t);
        const Real scale = absoluteSum(p.coefficients, t);
        // Contract: gamma(3n) Pbar(t); reference: kRefFactor(n) Pbar(t).
        const Real tolerance = (gamma(3 * n) + kRefFactor(n)) * scale;
        ASSERT_LE(std::fabs(evaluate(p, t) - reference), tolerance) << "n = " << n << ", t = " << t;
        ++checks;
      }
      // The ends are the end coefficients, exactly (s = 1, t = 0 or s = 0, t = 1).
      ASSERT_EQ(evaluate(p, 0.0), p.coefficients.front());
      ASSERT_EQ(evaluate(p, 1.0), p.coefficients.back());
    }
  }
  EXPECT_GT(checks, 20000);
}

TEST(BernsteinEvaluate, MatchesPowerBasisHorner) {
  std::mt19937_64 rng(42);
  for (int n = 0; n <= 25; ++n) {
    for (int trial = 0; trial < 60; ++trial) {
      const std::vector<double> a = randomCoefficients(rng, n);
      const std::vector<Real> aL(a.begin(), a.end());
      const Bernstein1 p = scallop::fromPowerBasis(a);
      ASSERT_EQ(p.degree(), n);
      for (double t : sampleParameters(rng, 12)) {
        // fromPowerBasis: c_i off by gamma(i + 2) Abar_i, Abar_i = sum_j C(i,j)/C(n,j) |a_j|,
        // and sum_i Abar_i b_i(t) = A(t) = sum_j |a_j| t^j; evaluate adds gamma(3n) Pbar(t)
        // <= gamma(3n) (1 + gamma(n + 2)) A(t); Horner in long double 2n uL A(t).
        const Real absolutePower = hornerAbs(aL, t);
        const Real tolerance =
            (gamma(n + 2) + gamma(3 * n) * (1 + gamma(n + 2)) + 2 * n * kUL) * absolutePower;
        ASSERT_LE(std::fabs(evaluate(p, t) - horner(aL, t)), tolerance)
            << "n = " << n << ", t = " << t;
      }
    }
  }
}

TEST(BernsteinDerivative, MatchesExplicitDerivativeOnIntegerCoefficients) {
  // Integer coefficients below 2^20: the differences n (c_{i+1} - c_i) are exact, so the only
  // rounding is the evaluation of the derivative, gamma(3(n - 1)) sum |d_i| b_i^{n-1}(t).
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> integer(-(1 << 20), 1 << 20);
  for (int n = 1; n <= 25; ++n) {
    for (int trial = 0; trial < 40; ++trial) {
      Bernstein1 p{std::vector<double>(n + 1)};
      for (double& c : p.coefficients) c = integer(rng);
      const Bernstein1 d = scallop::derivative(p);
      ASSERT_EQ(d.degree(), n - 1);
      for (int i = 0; i < n; ++i) {
        ASSERT_EQ(d.coefficients[i], n * (p.coefficients[i + 1] - p.coefficients[i]));
      }
      for (double t : sampleParameters(rng, 12)) {
        const auto [reference, magnitude] = explicitDerivative(p.coefficients, t);
        const Real tolerance =
            gamma(3 * (n - 1)) * absoluteSum(d.coefficients, t) + kRefFactor(n) * magnitude;
        ASSERT_LE(std::fabs(evaluate(d, t) - reference), tolerance) << "n = " << n;
      }
    }
  }
  // A constant's derivative is the zero constant.
  EXPECT_EQ(scallop::derivative(Bernstein1{{3.0}}).coefficients, std::vector<double>{0.0});
}

TEST(BernsteinDerivative, MatchesPowerBasisDerivative) {
  std::mt19937_64 rng(42);
  for (int n = 1; n <= 25; ++n) {
    for (int trial = 0; trial < 40; ++trial) {
      const std::vector<double> a = randomCoefficients(rng, n);
      std::vector<Real> da(n);
      for (int j = 1; j <= n; ++j) da[j - 1] = static_cast<Real>(j) * a[j];
      const Bernstein1 p = scallop::fromPowerBasis(a);
      const Bernstein1 d = scallop::derivative(p);
      // Abar_i as in MatchesPowerBasisHorner (the contract's bound on p's coefficients).
      std::vector<Real> abar(n + 1, 0);
      for (int i = 0; i <= n; ++i) {
        for (int j = 0; j <= i; ++j) abar[i] += binomialL(i, j) / binomialL(n, j) * std::fabs(a[j]);
      }
      for (double t : sampleParameters(rng, 10)) {
        // d_i = n (c_{i+1} - c_i): inherits n (|dc_{i+1}| + |dc_i|) <= n gamma(n + 2)
        // (Abar_{i+1} + Abar_i) and rounds twice (gamma(2) |d_i|); the evaluation adds
        // gamma(3(n - 1)) sum |d_i| b_i; Horner on j a_j: 2n uL sum j |a_j| t^(j-1).
        Real inherited = 0;
        for (int i = 0; i < n; ++i) inherited += (abar[i + 1] + abar[i]) * basisL(n - 1, i, t);
        const Real tolerance =
            n * gamma(n + 2) * inherited +
            (gamma(2) + gamma(3 * (n - 1)) * (1 + gamma(2))) * absoluteSum(d.coefficients, t) +
            2 * n * kUL * hornerAbs(da, t);
        ASSERT_LE(std::fabs(evaluate(d, t) - horner(da, t)), tolerance) << "n = " << n;
      }
    }
  }
}

TEST(BernsteinDerivative, MatchesFiniteDifferencesInLongDouble) {
  // Five-point stencil in long double on the explicit basis sum, h = 2^-12:
  //   |stencil - p'(t)| <= h^4 / 30 max|p^(5)|, max|p^(5)| <= n^5 2^5 max|c| (five forward
  //   differences of the coefficients, times n!/(n-5)! <= n^5), plus the stencil's rounding,
  //   (1 + 8 + 8 + 1) / (12 h) times the evaluation error kRefFactor(n) max Pbar.
  // A weak check by nature (the truncation term), kept as an independent sanity test.
  std::mt19937_64 rng(42);
  const Real h = std::ldexp(Real{1}, -12);
  for (int n = 1; n <= 12; ++n) {
    for (int trial = 0; trial < 50; ++trial) {
      const Bernstein1 p{randomCoefficients(rng, n)};
      const Bernstein1 d = scallop::derivative(p);
      const Real cmax = maxAbs(p.coefficients);
      for (int k = 0; k < 10; ++k) {
        const double t =
            2 * static_cast<double>(h) + randomUnit(rng) * (1 - 4 * static_cast<double>(h));
        const Real stencil =
            (explicitSum(p.coefficients, t - 2 * h) - 8 * explicitSum(p.coefficients, t - h) +
             8 * explicitSum(p.coefficients, t + h) - explicitSum(p.coefficients, t + 2 * h)) /
            (12 * h);
        const Real truncation = powInt(h, 4) / 30 * powInt(n, 5) * 32 * cmax;
        const Real rounding = 18 / (12 * h) * kRefFactor(n) * cmax;
        const Real tolerance =
            truncation + rounding + gamma(3 * n) * absoluteSum(d.coefficients, t);
        ASSERT_LE(std::fabs(evaluate(d, t) - stencil), tolerance) << "n = " << n;
      }
    }
  }
}

TEST(BernsteinMultiply, MatchesPointwiseProduct) {
  std::mt19937_64 rng(42);
  for (int m = 0; m <= 12; ++m) {
    for (int n = 0; n <= 12; ++n) {
      for (int trial = 0; trial < 8; ++trial) {
        const Bernstein1 p{randomCoefficients(rng, m)};
        const Bernstein1 q{randomCoefficients(rng, n)};
        const Bernstein1 r = scallop::multiply(p, q);
        ASSERT_EQ(r.degree(), m + n);
        for (double t : sampleParameters(rng, 10)) {
          // Contract: coefficient errors gamma(min(m,n) + 5) times the product of the
          // absolute polynomials (sum_k [sum_{i+j=k} w_ij |a_i||b_j|] b_k = Pbar Qbar), and the
          // evaluation gamma(3(m + n)) (1 + ...) Pbar Qbar; two references.
          const Real scale = absoluteSum(p.coefficients, t) * absoluteSum(q.coefficients, t);
          const Real tolerance =
              (gamma(std::min(m, n) + 5) + gamma(3 * (m + n)) * (1 + gamma(std::min(m, n) + 5)) +
               kRefFactor(m) + kRefFactor(n)) *
              scale;
          const Real reference = explicitSum(p.coefficients, t) * explicitSum(q.coefficients, t);
          ASSERT_LE(std::fabs(evaluate(r, t) - reference), tolerance)
              << "m = " << m << ", n = " << n << ", t = " << t;
        }
      }
    }
  }
}

TEST(BernsteinMultiply, ZeroPolynomialAndConstants) {
  const Bernstein1 zero{{0.0, 0.0, 0.0}};
  const Bernstein1 p{{1.0, -2.0, 3.0, 5.0}};
  const Bernstein1 product = scallop::multiply(zero, p);
  EXPECT_EQ(product.degree(), 5);
  EXPECT_TRUE(scallop::isZero(product));
  EXPECT_FALSE(scallop::isZero(p));
  // A constant multiplies every coefficient (weights C(0,0) C(n,j) / C(n,j) = 1 exactly).
  const Bernstein1 doubled = scallop::multiply(Bernstein1{{2.0}}, p);
  EXPECT_EQ(doubled.coefficients, (std::vector<double>{2.0, -4.0, 6.0, 10.0}));
  EXPECT_EQ(scallop::scale(p, 2.0).coefficients, doubled.coefficients);
  // (t)(1 - t) = b_1^2 / 2: {0, 1/2, 0}.
  EXPECT_EQ(scallop::multiply(Bernstein1{{0.0, 1.0}}, Bernstein1{{1.0, 0.0}}).coefficients,
            (std::vector<double>{0.0, 0.5, 0.0}));
}

TEST(BernsteinAdd, DifferentDegreesPointwise) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 400; ++trial) {
    const int m = trial % 11;
    const int n = (trial / 11) % 11;
    const Bernstein1 p{randomCoefficients(rng, m)};
    const Bernstein1 q{randomCoefficients(rng, n)};
    const Bernstein1 sum = scallop::add(p, q);
    const Bernstein1 difference = scallop::subtract(p, q);
    const int high = std::max(m, n);
    ASSERT_EQ(sum.degree(), high);
    ASSERT_EQ(difference.degree(), high);
    for (double t : sampleParameters(rng, 8)) {
      // Elevation gamma(min(low, r) + 4) <= gamma(high + 4) on the elevated operand, one
      // rounding for the sum, evaluation gamma(3 high): all times Pbar + Qbar.
      const Real scale = absoluteSum(p.coefficients, t) + absoluteSum(q.coefficients, t);
      const Real tolerance =
          (gamma(high + 4) + kU + gamma(3 * high) * (1 + gamma(high + 5)) + kRefFactor(high)) *
          scale;
      const Real pt = explicitSum(p.coefficients, t);
      const Real qt = explicitSum(q.coefficients, t);
      ASSERT_LE(std::fabs(evaluate(sum, t) - (pt + qt)), tolerance);
      ASSERT_LE(std::fabs(evaluate(difference, t) - (pt - qt)), tolerance);
    }
  }
}

TEST(BernsteinElevate, PreservesThePolynomial) {
  std::mt19937_64 rng(42);
  for (int n = 0; n <= 20; ++n) {
    for (int times : {0, 1, 2, 3, 7, 15}) {
      for (int trial = 0; trial < 10; ++trial) {
        const Bernstein1 p{randomCoefficients(rng, n)};
        const Bernstein1 e = scallop::elevate(p, times);
        ASSERT_EQ(e.degree(), n + times);
        // The ends are kept exactly (weight C(n,0) C(r,0) / C(n+r,0) = 1, a single term).
        ASSERT_EQ(e.coefficients.front(), p.coefficients.front());
        ASSERT_EQ(e.coefficients.back(), p.coefficients.back());
        for (double t : sampleParameters(rng, 10)) {
          // Contract: convex combinations off by gamma(min(n, r) + 4) times the elevation of
          // |c| (whose value is Pbar(t)); evaluation gamma(3(n + r)).
          const int k = std::min(n, times) + 4;
          const Real tolerance =
              (gamma(k) + gamma(3 * (n + times)) * (1 + gamma(k)) + kRefFactor(n)) *
              absoluteSum(p.coefficients, t);
          ASSERT_LE(std::fabs(evaluate(e, t) - explicitSum(p.coefficients, t)), tolerance);
        }
      }
    }
  }
  EXPECT_THROW(scallop::elevate(Bernstein1{{1.0}}, -1), scallop::Error);
  EXPECT_THROW(scallop::elevate(Bernstein1{{1.0}}, scallop::kMaxBernsteinDegree + 1),
               scallop::Error);
}

TEST(BernsteinSubdivide, PiecesReproduceThePolynomial) {
  std::mt19937_64 rng(42);
  for (int n = 0; n <= 25; ++n) {
    for (int trial = 0; trial < 30; ++trial) {
      const Bernstein1 p{randomCoefficients(rng, n)};
      const double t = trial == 0 ? 0.5 : randomUnit(rng);
      const auto [left, right] = scallop::subdivide(p, t);
      ASSERT_EQ(left.coefficients.front(), p.coefficients.front());
      ASSERT_EQ(right.coefficients.back(), p.coefficients.back());
      ASSERT_EQ(left.coefficients.back(), right.coefficients.front());  // the shared point
      const Real cmax = maxAbs(p.coefficients);
      for (int k = 0; k < 10; ++k) {
        const double s = k == 0 ? 0.0 : (k == 1 ? 1.0 : randomUnit(rng));
        // Contract: coefficients off by gamma(3n) times the subdivided |c| (value Pbar at the
        // mapped point); evaluation gamma(3n) (1 + gamma(3n)). The mapped point is computed
        // in long double (off by uL, moving p by <= 2n max|c| uL since |p'| <= 2n max|c|).
        const Real x = static_cast<Real>(t) * s;
        const Real y = static_cast<Real>(t) + (1 - static_cast<Real>(t)) * s;
        const Real factor = 2 * gamma(3 * n) + gamma(3 * n) * gamma(3 * n) + kRefFactor(n);
        ASSERT_LE(std::fabs(evaluate(left, s) - explicitSum(p.coefficients, x)),
                  factor * absoluteSum(p.coefficients, x) + 2 * n * cmax * kUL);
        ASSERT_LE(std::fabs(evaluate(right, s) - explicitSum(p.coefficients, y)),
                  factor * absoluteSum(p.coefficients, y) + 2 * n * cmax * kUL);
      }
      // Halving: every coefficient of a half is a convex combination computed as
      // (a + b) / 2, which rounding keeps within [min, max] (monotone rounding).
      const auto [l2, r2] = scallop::subdivide(p, 0.5);
      const scallop::Bounds b = scallop::bounds(p);
      for (const Bernstein1* half : {&l2, &r2}) {
        const scallop::Bounds hb = scallop::bounds(*half);
        ASSERT_GE(hb.lo, b.lo);
        ASSERT_LE(hb.hi, b.hi);
      }
    }
  }
}

TEST(BernsteinRestrict, MatchesReparametrisation) {
  std::mt19937_64 rng(42);
  for (int n = 0; n <= 20; ++n) {
    for (int trial = 0; trial < 40; ++trial) {
      const Bernstein1 p{randomCoefficients(rng, n)};
      double a = randomUnit(rng);
      double b = randomUnit(rng);
      if (trial % 10 == 0) b = a;                                // a point: the constant p(a)
      if (trial % 10 == 1) std::swap(a, b);                      // both orders
      if (trial % 10 == 2) a = 0.0, b = randomUnit(rng) * 1e-6;  // a sliver at 0
      if (trial % 10 == 3) a = 1.0, b = 0.0;                     // reversal
      const Bernstein1 q = scallop::restrictTo(p, a, b);
      ASSERT_EQ(q.degree(), n);
      const Real cmax = maxAbs(p.coefficients);
      for (int k = 0; k < 8; ++k) {
        const double s = k == 0 ? 0.0 : (k == 1 ? 1.0 : randomUnit(rng));
        const Real x = a + (static_cast<Real>(b) - a) * s;
        // Contract gamma(6n) Pbar(x) for the coefficients, evaluation gamma(3n); the division
        // a / b (or (b - a) / (1 - a)) moves the interval's end by <= 3u (2|a| + |b|), which
        // moves p by at most max|p'| <= 2n max|c| times that.
        const Real tolerance = (gamma(6 * n) + gamma(3 * n) * (1 + gamma(6 * n)) + kRefFactor(n)) *
                                   absoluteSum(p.coefficients, x) +
                               2 * n * cmax * 3 * kU * (2 * std::fabs(a) + std::fabs(b));
        ASSERT_LE(std::fabs(evaluate(q, s) - explicitSum(p.coefficients, x)), tolerance)
            << "n = " << n << ", [" << a << ", " << b << "], s = " << s;
      }
    }
  }
}

TEST(BernsteinBounds, ContainSampledValues) {
  std::mt19937_64 rng(42);
  for (int n = 0; n <= 25; ++n) {
    for (int trial = 0; trial < 40; ++trial) {
      const Bernstein1 p{randomCoefficients(rng, n)};
      const scallop::Bounds b = scallop::bounds(p);
      ASSERT_LE(b.lo, b.hi);
      for (double t : sampleParameters(rng, 20)) {
        // The exact value lies in [lo, hi] (convex hull); the computed one may stray by the
        // evaluation error gamma(3n) Pbar(t).
        const double tolerance = gamma(3 * n) * static_cast<double>(absoluteSum(p.coefficients, t));
        const double value = evaluate(p, t);
        ASSERT_GE(value, b.lo - tolerance);
        ASSERT_LE(value, b.hi + tolerance);
        ASSERT_GE(static_cast<double>(explicitSum(p.coefficients, t)), b.lo - tolerance);
      }
    }
  }
}

TEST(BernsteinSignVariations, CountsSignChangesSkippingZeros) {
  EXPECT_EQ(scallop::signVariations(Bernstein1{{1.0, -1.0, 1.0}}), 2);
  EXPECT_EQ(scallop::signVariations(Bernstein1{{0.0, 1.0, 0.0, -1.0}}), 1);
  EXPECT_EQ(scallop::signVariations(Bernstein1{{0.0, 0.0}}), 0);
  EXPECT_EQ(scallop::signVariations(Bernstein1{{1.0, 0.0, 0.0, 1.0}}), 0);
  EXPECT_EQ(scallop::signVariations(Bernstein1{{-1.0, 0.0, 2.0, -3.0, 0.0, 0.0, 4.0}}), 3);
  EXPECT_EQ(scallop::signVariations(Bernstein1{{-0.0, 1.0}}), 0);
  // Variation diminishing: never fewer variations than roots in (0, 1).
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 500; ++trial) {
    const Bernstein1 p{randomCoefficients(rng, 1 + trial % 15)};
    int rootsInside = 0;
    for (const RootInterval& r : scallop::isolateRoots(p)) {
      if (r.lo > 0.0 && r.hi < 1.0 && !r.cluster) rootsInside += r.count;
    }
    ASSERT_GE(scallop::signVariations(p), rootsInside);
  }
}

TEST(BernsteinPowerBasis, ExactSmallCasesAndRoundTrip) {
  EXPECT_EQ(scallop::fromPowerBasis({0.0, 1.0}).coefficients, (std::vector<double>{0.0, 1.0}));
  EXPECT_EQ(scallop::fromPowerBasis({0.0, 0.0, 1.0}).coefficients,
            (std::vector<double>{0.0, 0.0, 1.0}));
  EXPECT_EQ(scallop::fromPowerBasis({1.0, 1.0}).coefficients, (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(scallop::fromPowerBasis({7.0}).coefficients, std::vector<double>{7.0});
  // 2t(1 - t) / 2 + t^2 = t.
  EXPECT_EQ(scallop::toPowerBasis(Bernstein1{{0.0, 0.5, 1.0}}),
            (std::vector<double>{0.0, 1.0, 0.0}));
  EXPECT_THROW(scallop::fromPowerBasis({}), scallop::Error);

  std::mt19937_64 rng(42);
  for (int n = 0; n <= 10; ++n) {
    for (int trial = 0; trial < 50; ++trial) {
      const std::vector<double> a = randomCoefficients(rng, n);
      const Bernstein1 p = scallop::fromPowerBasis(a);
      const std::vector<double> back = scallop::toPowerBasis(p);
      ASSERT_EQ(static_cast<int>(back.size()), n + 1);
      // a_j = C(n,j) sum_i (-1)^(j-i) C(j,i) c_i: the c_i carry gamma(n + 2) Abar_i (contract)
      // and the conversion back rounds gamma(j + 3) relative to C(n,j) sum C(j,i) |c_i|.
      for (int j = 0; j <= n; ++j) {
        Real bound = 0;
        for (int i = 0; i <= j; ++i) {
          Real abar = 0;
          for (int k = 0; k <= i; ++k) abar += binomialL(i, k) / binomialL(n, k) * std::fabs(a[k]);
          bound +=
              binomialL(j, i) * (gamma(n + 2) * abar + gamma(j + 3) * std::fabs(p.coefficients[i]));
        }
        bound *= binomialL(n, j);
        ASSERT_LE(std::fabs(back[j] - a[j]), bound) << "n = " << n << ", j = " << j;
      }
    }
  }
}

TEST(BernsteinErrors, InvalidInputsThrow) {
  const Bernstein1 empty;
  EXPECT_EQ(empty.degree(), -1);
  EXPECT_THROW(evaluate(empty, 0.5), scallop::Error);
  EXPECT_THROW(scallop::derivative(empty), scallop::Error);
  EXPECT_THROW(scallop::isolateRoots(empty), scallop::Error);
  EXPECT_THROW(scallop::isolateRoots(Bernstein1{{1.0, std::nan(""), -1.0}}), scallop::Error);
  EXPECT_THROW(scallop::isolateRoots(Bernstein1{{1.0, -1.0}}, RootOptions{-1.0, 60}),
               scallop::Error);
  EXPECT_THROW(scallop::isolateRoots(Bernstein1{{1.0, -1.0}}, RootOptions{1e-12, -1}),
               scallop::Error);
  Bernstein1 tooHigh{std::vector<double>(600, 1.0)};
  EXPECT_THROW(scallop::multiply(tooHigh, tooHigh), scallop::Error);
  EXPECT_THROW(evaluate(Bernstein2{2, 2, {1.0}}, 0.5, 0.5), scallop::Error);
  EXPECT_THROW(evaluate(Bernstein2{-1, 0, {}}, 0.5, 0.5), scallop::Error);
}

// ---------------------------------------------------------------------------------------
// Roots: polynomials built from known roots
// ---------------------------------------------------------------------------------------

// prod (t - r_i) prod ((t - a)^2 + b^2), scaled by a power of two so that max |c| is in
// [1/2, 1), multiplied out in long double with a running bound on the construction error.
struct KnownPolynomial {
  std::vector<Real> roots;  // real roots, repeated with multiplicity
  std::vector<std::pair<Real, Real>> complexPairs;
  Bernstein1 p;             // rounded to double: within one rounding of `exact`
  std::vector<Real> exact;  // long double coefficients
  std::vector<Real> error;  // |exact_i - ideal_i| <= error_i
  Real scale = 1;           // p* = scale prod(...)
};

KnownPolynomial buildPolynomial(std::vector<Real> roots,
                                std::vector<std::pair<Real, Real>> pairs = {}) {
  KnownPolynomial k;
  k.roots = std::move(roots);
  k.complexPairs = std::move(pairs);
  std::vector<Real> c = {1};
  std::vector<Real> e = {0};
  // Times (t - r) = -r b_0^1 + (1 - r) b_1^1: q_k = -r (n+1-k)/(n+1) p_k + (1-r) k/(n+1) p_{k-1};
  // weights (2 roundings), 1 - r (1), products (2), sum (1): charged 8 uL per term.
  for (Real r : k.roots) {
    const int n = static_cast<int>(c.size()) - 1;
    std::vector<Real> q(n + 2, 0);
    std::vector<Real> qe(n + 2, 0);
    for (int i = 0; i <= n + 1; ++i) {
      const Real alpha = -r * (n + 1 - i) / (n + 1);
      const Real beta = (1 - r) * i / (n + 1);
      const Real x = i <= n ? alpha * c[i] : 0;
      const Real y = i >= 1 ? beta * c[i - 1] : 0;
      q[i] = x + y;
      qe[i] = (i <= n ? std::fabs(alpha) * e[i] : 0) + (i >= 1 ? std::fabs(beta) * e[i - 1] : 0) +
              8 * kUL * (std::fabs(x) + std::fabs(y));
    }
    c = q;
    e = qe;
  }
  // Times (t - a)^2 + b^2 = d_0 b_0^2 + d_1 b_1^2 + d_2 b_2^2 with d_0 = a^2 + b^2,
  // d_1 = a^2 + b^2 - a, d_2 = (1 - a)^2 + b^2 (each within 4 uL |d_j| + 4 uL (a^2 + b^2 + |a|)).
  for (const auto& [a, b] : k.complexPairs) {
    const Real d[3] = {a * a + b * b, a * a + b * b - a, (1 - a) * (1 - a) + b * b};
    const Real dAbs[3] = {a * a + b * b, a * a + b * b + std::fabs(a), (1 - a) * (1 - a) + b * b};
    const int n = static_cast<int>(c.size()) - 1;
    std::vector<Real> q(n + 3, 0);
    std::vector<Real> qe(n + 3, 0);
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; j <= 2; ++j) {
        const Real w = binomialL(n, i) * binomialL(2, j) / binomialL(n + 2, i + j);
        q[i + j] += w * c[i] * d[j];
        qe[i + j] += w * (e[i] * dAbs[j] + 12 * kUL * std::fabs(c[i]) * dAbs[j]);
      }
    }
    c = q;
    e = qe;
  }
  Real cmax = 0;
  for (Real x : c) cmax = std::max(cmax, std::fabs(x));
  const int exponent = std::ilogb(cmax) + 1;  // max |c| 2^-exponent in [1/2, 1)
  k.scale = std::ldexp(Real{1}, -exponent);
  k.exact.resize(c.size());
  k.error.resize(c.size());
  k.p.coefficients.resize(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    k.exact[i] = c[i] * k.scale;
    k.error[i] = e[i] * k.scale;
    k.p.coefficients[i] = static_cast<double>(k.exact[i]);
  }
  return k;
}

// |p*^(mu)(r)| / mu! for the group of roots within `radius` of r counted as one root of
// multiplicity mu: scale times the product over the other factors at r.
std::pair<int, Real> groupDerivative(const KnownPolynomial& k, Real r, Real radius) {
  int mu = 0;
  Real v = k.scale;
  for (Real x : k.roots) {
    if (std::fabs(x - r) <= radius) {
      ++mu;
    } else {
      v *= r - x;
    }
  }
  for (const auto& [a, b] : k.complexPairs) v *= (r - a) * (r - a) + b * b;
  return {mu, std::fabs(v)};
}

Real constructionError(const KnownPolynomial& k, Real t) {
  const int n = static_cast<int>(k.error.size()) - 1;
  Real s = 0;
  for (int i = 0; i <= n; ++i) s += k.error[i] * basisL(n, i, t);
  return s;
}

// Roots closer than this to each other are treated as one group of multiplicity mu for the
// perturbation radius (the first-order simple-root formula needs rho << gap).
constexpr Real kGroupRadius = 1e-5;

// rho: twice the first-order displacement (Delta / D)^(1/mu) of the group, plus its diameter.
Real perturbationRadius(const KnownPolynomial& k, Real r) {
  const auto [mu, d] = groupDerivative(k, r, kGroupRadius);
  Real lo = r;
  Real hi = r;
  for (Real x : k.roots) {
    if (std::fabs(x - r) <= kGroupRadius) lo = std::min(lo, x), hi = std::max(hi, x);
  }
  const Real delta = constructionError(k, r);
  return 2 * std::pow(delta / d, Real{1} / mu) + (hi - lo) +
         std::numeric_limits<double>::denorm_min();
}

int rootsInUnitInterval(const KnownPolynomial& k) {
  int count = 0;
  for (Real r : k.roots) count += (r >= 0 && r <= 1) ? 1 : 0;
  return count;
}

struct RootCheckStats {
  int simple = 0;
  int clusters = 0;
  Real worstSimpleRatio = 0;  // |error| / tolerance, largest seen
};

// The checks every root test shares: sorted disjoint intervals inside [0, 1]; every known
// root in [0, 1] covered (within rho); counts adding up to the known multiplicity;
// realRoots consistent with the intervals; simple roots refined to the derived tolerance.
void checkRoots(const KnownPolynomial& k, const std::string& label, RootCheckStats* stats = nullptr,
                const RootOptions& options = {}) {
  const std::vector<RootInterval> intervals = scallop::isolateRoots(k.p, options);
  const std::vector<double> roots = scallop::realRoots(k.p, options);
  const int n = k.p.degree();
  int total = 0;
  for (std::size_t i = 0; i < intervals.size(); ++i) {
    const RootInterval& I = intervals[i];
    ASSERT_LE(0.0, I.lo) << label;
    ASSERT_LE(I.lo, I.hi) << label;
    ASSERT_LE(I.hi, 1.0) << label;
    ASSERT_GE(I.count, 1) << label;
    if (!I.cluster) {
      ASSERT_EQ(I.count, 1) << label;
    }
    if (i > 0) {
      ASSERT_LE(intervals[i - 1].hi, I.lo) << label;
    }
    total += I.count;
  }
  ASSERT_EQ(total, rootsInUnitInterval(k)) << label;
  ASSERT_EQ(static_cast<int>(roots.size()), total) << label;
  ASSERT_TRUE(std::is_sorted(roots.begin(), roots.end())) << label;
  for (Real r : k.roots) {
    if (r < 0 || r > 1) continue;
    const Real rho = perturbationRadius(k, r);
    const bool covered =
        std::any_of(intervals.begin(), intervals.end(),
                    [&](const RootInterval& I) { return I.lo - rho <= r && r <= I.hi + rho; });
    ASSERT_TRUE(covered) << label << ": root " << static_cast<double>(r) << " lost (rho "
                         << static_cast<double>(rho) << ")";
  }
  std::size_t next = 0;
  for (const RootInterval& I : intervals) {
    for (int c = 0; c < I.count; ++c, ++next) {
      const double x = roots[next];
      if (I.cluster || I.lo == I.hi) {
        ASSERT_EQ(x, I.lo + 0.5 * (I.hi - I.lo)) << label;
        continue;
      }
      ASSERT_GE(x, I.lo) << label;
      ASSERT_LE(x, I.hi) << label;
      // The nearest known root, which must be simple (a certified interval holds one).
      Real best = k.roots.front();
      for (Real r : k.roots) {
        if (std::fabs(r - x) < std::fabs(best - x)) best = r;
      }
      const auto [mu, d] = groupDerivative(k, best, 0);
      ASSERT_EQ(mu, 1) << label << ": a certified simple root near a multiple root";
      const Real tolerance = 2 * (3 * n + 1) * kU * absoluteSum(k.p.coefficients, best) / d +
                             perturbationRadius(k, best) + 4 * kU * std::fabs(best);
      const Real error = std::fabs(x - best);
      ASSERT_LE(error, tolerance) << label << ": root " << static_cast<double>(best)
                                  << " refined to " << x;
      if (stats != nullptr) {
        ++stats->simple;
        stats->worstSimpleRatio = std::max(stats->worstSimpleRatio, error / tolerance);
      }
    }
    if (stats != nullptr && I.cluster) ++stats->clusters;
  }
}

TEST(BernsteinRoots, LinearPolynomialsToMachinePrecision) {
  std::mt19937_64 rng(42);
  RootCheckStats stats;
  for (int trial = 0; trial < 2000; ++trial) {
    const Real r = trial < 5 ? Real{0.25} * trial : static_cast<Real>(randomUnit(rng));
    const KnownPolynomial k = buildPolynomial({r});
    checkRoots(k, "linear", &stats);
  }
  std::printf("[          ] linear: %d simple roots, worst error / tolerance %.3g\n", stats.simple,
              static_cast<double>(stats.worstSimpleRatio));
}

TEST(BernsteinRoots, NoRootsInTheInterval) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> outside(0.01, 2.0);
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<Real> roots;
    std::vector<std::pair<Real, Real>> pairs;
    const int count = 1 + trial % 8;
    for (int i = 0; i < count; ++i) {
      const double d = outside(rng);
      roots.push_back(i % 2 == 0 ? -d : 1 + d);
    }
    for (int i = 0; i < trial % 3; ++i) pairs.push_back({randomUnit(rng), 0.05 + randomUnit(rng)});
    const KnownPolynomial k = buildPolynomial(roots, pairs);
    ASSERT_TRUE(scallop::isolateRoots(k.p).empty()) << trial;
    ASSERT_TRUE(scallop::realRoots(k.p).empty()) << trial;
  }
  // Positive coefficients, and a nonzero constant.
  EXPECT_TRUE(scallop::isolateRoots(Bernstein1{{1.0, 2.0, 0.5, 3.0}}).empty());
  EXPECT_TRUE(scallop::realRoots(Bernstein1{{-2.0}}).empty());
}

TEST(BernsteinRoots, ExactRootsAtTheEnds) {
  // t^k0 (1 - t)^k1 (t - 0.3)(t - 0.7): the zero coefficients are exact, so the ends are
  // reported as [0, 0] and [1, 1] with their multiplicities.
  for (int k0 = 0; k0 <= 4; ++k0) {
    for (int k1 = 0; k1 <= 4; ++k1) {
      std::vector<Real> roots(k0, Real{0});
      roots.insert(roots.end(), k1, Real{1});
      roots.push_back(Real{0.3});
      roots.push_back(Real{0.7});
      const KnownPolynomial k = buildPolynomial(roots);
      const std::string label = "ends " + std::to_string(k0) + ", " + std::to_string(k1);
      checkRoots(k, label);
      const std::vector<RootInterval> intervals = scallop::isolateRoots(k.p);
      const std::vector<double> values = scallop::realRoots(k.p);
      if (k0 > 0) {
        ASSERT_EQ(intervals.front().lo, 0.0);
        ASSERT_EQ(intervals.front().hi, 0.0);
        ASSERT_EQ(intervals.front().count, k0);
        ASSERT_EQ(intervals.front().cluster, k0 > 1);
        ASSERT_EQ(std::count(values.begin(), values.end(), 0.0), k0);
      }
      if (k1 > 0) {
        ASSERT_EQ(intervals.back().lo, 1.0);
        ASSERT_EQ(intervals.back().count, k1);
        ASSERT_EQ(std::count(values.begin(), values.end(), 1.0), k1);
      }
    }
  }
}

TEST(BernsteinRoots, RootsJustInsideAndJustOutside) {
  // The end values c_0 = p(0), c_n = p(1) are not rounded by the algorithm and the family
  // perturbs them relatively, so a root a hair outside stays outside and one a hair inside
  // stays inside.
  const std::vector<Real> offsets = {1e-3L, 1e-8L, 1e-10L, 1e-13L, 1e-15L, 1e-30L};
  for (Real d : offsets) {
    for (int side = 0; side < 4; ++side) {
      const Real r = side == 0 ? -d : (side == 1 ? d : (side == 2 ? 1 - d : 1 + d));
      const KnownPolynomial k = buildPolynomial({r, Real{0.4}, Real{0.6}});
      checkRoots(
          k, "offset " + std::to_string(static_cast<double>(d)) + " side " + std::to_string(side));
    }
  }
}

TEST(BernsteinRoots, ClosePairs) {
  // Pairs 1e-3 .. 1e-12 apart next to other roots. Every root is covered and the pair counts
  // two; a pair is separated into two certified simple roots when the gap exceeds the noise
  // radius of a double root, which we count and print.
  std::mt19937_64 rng(42);
  RootCheckStats stats;
  int separated = 0;
  int pairs = 0;
  std::string perGap;
  for (int exponent = 3; exponent <= 12; ++exponent) {
    int separatedAtGap = 0;
    const Real gap = std::pow(Real{10}, -exponent);
    for (int trial = 0; trial < 60; ++trial) {
      const Real centre = 0.1L + 0.8L * randomUnit(rng);
      std::vector<Real> roots = {centre - gap / 2, centre + gap / 2};
      const int others = trial % 4;
      for (int i = 0; i < others; ++i) {
        Real r;
        do r = randomUnit(rng);
        while (std::fabs(r - centre) < 0.02L);
        roots.push_back(r);
      }
      const KnownPolynomial k = buildPolynomial(roots);
      checkRoots(k, "gap 1e-" + std::to_string(exponent), &stats);
      // Separated: each root of the pair in its own certified simple interval.
      int simpleNearPair = 0;
      for (const RootInterval& I : scallop::isolateRoots(k.p)) {
        const bool holdsLeft = I.lo <= roots[0] && roots[0] <= I.hi;
        const bool holdsRight = I.lo <= roots[1] && roots[1] <= I.hi;
        if (!I.cluster && holdsLeft != holdsRight) ++simpleNearPair;
      }
      ++pairs;
      separated += simpleNearPair == 2 ? 1 : 0;
      separatedAtGap += simpleNearPair == 2 ? 1 : 0;
      if (exponent <= 6) {
        ASSERT_EQ(simpleNearPair, 2) << "gap 1e-" << exponent << " not separated";
      }
    }
    perGap += " 1e-" + std::to_string(exponent) + ":" + std::to_string(separatedAtGap);
  }
  std::printf(
      "[          ] close pairs: %d of %d separated (per gap, of 60:%s); %d simple "
      "roots, worst error / tolerance %.3g\n",
      separated, pairs, perGap.c_str(), stats.simple, static_cast<double>(stats.worstSimpleRatio));
}

// Half-width of the noise band of a root of multiplicity mu (see the header's cluster width):
// coefficients carry at most E = (1 + 2 n D) u max|c| after D halvings, and an interval stops
// as "all uncertain" only where |p| <= 2E plus the family's u Pbar <= E, so within
// (3E / D_mu)^(1/mu) of the root (first order); 10% for the neglected higher-order terms.
Real noiseHalfWidth(const KnownPolynomial& k, Real r, int depth) {
  const int n = k.p.degree();
  const auto [mu, d] = groupDerivative(k, r, 0);
  const Real e = (1 + 2 * n * depth) * kU * maxAbs(k.p.coefficients);
  return 1.1L * std::pow(3 * e / d, Real{1} / mu);
}

TEST(BernsteinRoots, MultipleRoots) {
  std::mt19937_64 rng(42);
  int clusters = 0;
  Real worstWidthRatio = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const int multiplicity = 2 + trial % 3;  // double, triple, quadruple
    // Exact dyadic roots first (their powers (t - r)^mu have exact coefficients), then random.
    const Real r =
        trial < 30 ? Real{0.5} + (trial % 5 - 2) * Real{0.125} : 0.05L + 0.9L * randomUnit(rng);
    std::vector<Real> roots(multiplicity, r);
    const int others = trial % 4;
    for (int i = 0; i < others; ++i) {
      Real x;
      do x = randomUnit(rng);
      while (std::fabs(x - r) < 0.05L);
      roots.push_back(x);
    }
    const KnownPolynomial k = buildPolynomial(roots);
    const std::string label = "multiplicity " + std::to_string(multiplicity) + " at " +
                              std::to_string(static_cast<double>(r));
    checkRoots(k, label);
    // The cluster holding r: count mu, narrower than the noise band (+ two leaves at the
    // resolution on its sides).
    const std::vector<RootInterval> intervals = scallop::isolateRoots(k.p);
    const auto it = std::find_if(intervals.begin(), intervals.end(),
                                 [&](const RootInterval& I) { return I.lo <= r && r <= I.hi; });
    ASSERT_NE(it, intervals.end()) << label;
    ASSERT_TRUE(it->cluster) << label;
    ASSERT_EQ(it->count, multiplicity) << label;
    const Real limit = 2 * noiseHalfWidth(k, r, 40) + 4e-12L;
    ASSERT_LE(it->hi - it->lo, limit) << label;
    worstWidthRatio = std::max(worstWidthRatio, (it->hi - it->lo) / limit);
    ++clusters;
  }
  std::printf("[          ] multiple roots: %d clusters, widest / noise band %.3g\n", clusters,
              static_cast<double>(worstWidthRatio));
}

TEST(BernsteinRoots, HighMultiplicity) {
  // (t - 1/2)^k: exact coefficients (-1/2)^(k-i) (1/2)^i; one cluster of count k holding 1/2.
  for (int multiplicity = 2; multiplicity <= 14; ++multiplicity) {
    const KnownPolynomial k = buildPolynomial(std::vector<Real>(multiplicity, Real{0.5}));
    checkRoots(k, "(t - 1/2)^" + std::to_string(multiplicity));
    const std::vector<RootInterval> intervals = scallop::isolateRoots(k.p);
    ASSERT_EQ(intervals.size(), 1u);
    EXPECT_EQ(intervals[0].count, multiplicity);
  }
  // (t - 0.3)^5 (t - 0.7)^3 (t - 0.9): two clusters and a simple root.
  std::vector<Real> roots(5, 0.3L);
  roots.insert(roots.end(), 3, 0.7L);
  roots.push_back(0.9L);
  checkRoots(buildPolynomial(roots), "(t-0.3)^5 (t-0.7)^3 (t-0.9)");
}

TEST(BernsteinRoots, WilkinsonLikeHighDegree) {
  // Equally spaced roots filling [0, 1]: well conditioned in Bernstein form (Farouki & Rajan
  // 1987), so every root is certified simple and refined to near machine precision.
  RootCheckStats stats;
  for (int n : {10, 15, 20, 25, 30}) {
    std::vector<Real> roots;
    for (int i = 1; i <= n; ++i) roots.push_back((i - 0.5L) / n);
    const KnownPolynomial k = buildPolynomial(roots);
    checkRoots(k, "wilkinson " + std::to_string(n), &stats);
    const std::vector<RootInterval> intervals = scallop::isolateRoots(k.p);
    ASSERT_EQ(static_cast<int>(intervals.size()), n);
    for (const RootInterval& I : intervals) ASSERT_FALSE(I.cluster) << n;
  }
  // With both ends: i / 20, i = 0 .. 20 (degree 21).
  std::vector<Real> roots;
  for (int i = 0; i <= 20; ++i) roots.push_back(i / 20.0L);
  checkRoots(buildPolynomial(roots), "wilkinson with ends", &stats);
  std::printf("[          ] wilkinson: %d simple roots, worst error / tolerance %.3g\n",
              stats.simple, static_cast<double>(stats.worstSimpleRatio));
}

TEST(BernsteinRoots, RandomRootGroups) {
  // Thousands of polynomials of degree up to 20 mixing simple roots, close pairs (gaps
  // 1e-2 .. 1e-11), double and triple roots, roots outside [0, 1], complex pairs, and exact
  // roots at the ends; groups at least 0.02 apart.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> kind(0.0, 1.0);
  RootCheckStats stats;
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<Real> roots;
    std::vector<std::pair<Real, Real>> pairs;
    std::vector<Real> centres;
    const int groups = 1 + trial % 6;
    int degree = 0;
    for (int g = 0; g < groups && degree <= 16; ++g) {
      Real c;
      int attempts = 0;
      do {
        c = 0.02L + 0.96L * randomUnit(rng);
      } while (++attempts < 100 && std::any_of(centres.begin(), centres.end(),
                                               [&](Real x) { return std::fabs(x - c) < 0.02L; }));
      centres.push_back(c);
      const double k = kind(rng);
      if (k < 0.45) {
        roots.push_back(c);
        degree += 1;
      } else if (k < 0.6) {
        const Real gap = std::pow(Real{10}, -(2 + static_cast<int>(10 * randomUnit(rng))));
        roots.push_back(c - gap / 2);
        roots.push_back(c + gap / 2);
        degree += 2;
      } else if (k < 0.75) {
        roots.insert(roots.end(), 2, c);
        degree += 2;
      } else if (k < 0.82) {
        roots.insert(roots.end(), 3, c);
        degree += 3;
      } else if (k < 0.9) {
        roots.push_back(randomUnit(rng) < 0.5 ? -c : 1 + c);
        degree += 1;
      } else {
        pairs.push_back({c, 0.01L + 0.3L * randomUnit(rng)});
        degree += 2;
      }
    }
    if (trial % 10 == 0) roots.push_back(0);
    if (trial % 15 == 0) roots.push_back(1);
    if (roots.empty() && pairs.empty()) roots.push_back(0.5L);
    checkRoots(buildPolynomial(roots, pairs), "random " + std::to_string(trial), &stats);
  }
  std::printf(
      "[          ] random groups: %d simple roots (worst error / tolerance %.3g), %d clusters\n",
      stats.simple, static_cast<double>(stats.worstSimpleRatio), stats.clusters);
}

TEST(BernsteinRoots, CoarseResolutionReportsUnseparatedPairs) {
  // With resolution 1e-3, a pair 1e-6 apart stays one unresolved interval: count 2, cluster.
  const KnownPolynomial k = buildPolynomial({0.3L, 0.3L + 1e-6L, 0.8L});
  const RootOptions coarse{1e-3, 60};
  checkRoots(k, "coarse", nullptr, coarse);
  const std::vector<RootInterval> intervals = scallop::isolateRoots(k.p, coarse);
  ASSERT_EQ(intervals.size(), 2u);
  EXPECT_TRUE(intervals[0].cluster);
  EXPECT_EQ(intervals[0].count, 2);
  EXPECT_LE(intervals[0].hi - intervals[0].lo, 2e-3);
  EXPECT_FALSE(intervals[1].cluster);
  // maxDepth 0: [0, 1] itself is the only interval; it holds three roots.
  const std::vector<RootInterval> top = scallop::isolateRoots(k.p, RootOptions{1e-12, 0});
  ASSERT_EQ(top.size(), 1u);
  EXPECT_EQ(top[0].count, 3);
}

TEST(BernsteinRoots, ZeroPolynomial) {
  const Bernstein1 zero{{0.0, 0.0, 0.0, 0.0}};
  EXPECT_TRUE(scallop::isZero(zero));
  const std::vector<RootInterval> intervals = scallop::isolateRoots(zero);
  ASSERT_EQ(intervals.size(), 1u);
  EXPECT_EQ(intervals[0].lo, 0.0);
  EXPECT_EQ(intervals[0].hi, 1.0);
  EXPECT_EQ(intervals[0].count, 0);
  EXPECT_TRUE(intervals[0].cluster);
  EXPECT_THROW(scallop::realRoots(zero), scallop::Error);
  EXPECT_EQ(scallop::bounds(zero).lo, 0.0);
  EXPECT_EQ(scallop::signVariations(zero), 0);
}

TEST(BernsteinRoots, TransformedInputs) {
  // Scaling by a power of two changes nothing (every operation scales exactly); mirroring
  // t -> 1 - t mirrors the intervals exactly (halving is symmetric); determinism.
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Real> roots;
    for (int i = 0; i < 1 + trial % 9; ++i) roots.push_back(randomUnit(rng));
    if (trial % 3 == 0) roots.push_back(roots.front());
    const KnownPolynomial k = buildPolynomial(roots);
    const std::vector<RootInterval> base = scallop::isolateRoots(k.p);
    const std::vector<RootInterval> scaled = scallop::isolateRoots(scallop::scale(k.p, 1024.0));
    const Bernstein1 mirrored{{k.p.coefficients.rbegin(), k.p.coefficients.rend()}};
    const std::vector<RootInterval> mirror = scallop::isolateRoots(mirrored);
    ASSERT_EQ(base.size(), scaled.size());
    ASSERT_EQ(base.size(), mirror.size());
    for (std::size_t i = 0; i < base.size(); ++i) {
      const RootInterval& m = mirror[base.size() - 1 - i];
      ASSERT_EQ(base[i].lo, scaled[i].lo);
      ASSERT_EQ(base[i].hi, scaled[i].hi);
      ASSERT_EQ(base[i].count, scaled[i].count);
      ASSERT_EQ(base[i].lo, 1.0 - m.hi);
      ASSERT_EQ(base[i].hi, 1.0 - m.lo);
      ASSERT_EQ(base[i].count, m.count);
      ASSERT_EQ(base[i].cluster, m.cluster);
    }
    ASSERT_EQ(scallop::realRoots(k.p), scallop::realRoots(k.p));
  }
}

// ---------------------------------------------------------------------------------------
// Tensor product
// ---------------------------------------------------------------------------------------

Bernstein2 randomBernstein2(std::mt19937_64& rng, int m, int n) {
  return {m, n, randomCoefficients(rng, (m + 1) * (n + 1) - 1)};
}

Real explicitSum2(const Bernstein2& p, Real u, Real v, bool absolute = false) {
  Real s = 0;
  for (int i = 0; i <= p.degreeU; ++i) {
    for (int j = 0; j <= p.degreeV; ++j) {
      const Real c = absolute ? std::fabs(static_cast<Real>(p.at(i, j))) : p.at(i, j);
      s += c * basisL(p.degreeU, i, u) * basisL(p.degreeV, j, v);
    }
  }
  return s;
}

Real kRefFactor2(int m, int n) { return (4 * (m + n) + 12) * kUL; }

TEST(Bernstein2Evaluate, MatchesDoubleLoop) {
  std::mt19937_64 rng(42);
  for (int m = 0; m <= 8; ++m) {
    for (int n = 0; n <= 8; ++n) {
      for (int trial = 0; trial < 10; ++trial) {
        const Bernstein2 p = randomBernstein2(rng, m, n);
        ASSERT_EQ(p.at(m, n), p.coefficients.back());
        for (int k = 0; k < 12; ++k) {
          const double u = k == 0 ? 0.0 : randomUnit(rng);
          const double v = k == 1 ? 1.0 : randomUnit(rng);
          // Contract: gamma(3(m + n)) Pbar(u, v) (rows in v, then the column in u).
          const Real tolerance =
              (gamma(3 * (m + n)) + kRefFactor2(m, n)) * explicitSum2(p, u, v, true);
          ASSERT_LE(std::fabs(evaluate(p, u, v) - explicitSum2(p, u, v)), tolerance);
        }
      }
    }
  }
}

TEST(Bernstein2Derivative, MatchesExplicitDerivatives) {
  // Integer coefficients: the differences are exact (see the univariate test), so
  // derivativeU(p)(u, v) differs from the explicit derivative by the evaluation error only.
  std::mt19937_64 rng(42);
  std::uniform_int_distribution<int> integer(-1000, 1000);
  for (int m = 0; m <= 6; ++m) {
    for (int n = 0; n <= 6; ++n) {
      Bernstein2 p{m, n, std::vector<double>((m + 1) * (n + 1))};
      for (double& c : p.coefficients) c = integer(rng);
      const Bernstein2 du = scallop::derivativeU(p);
      const Bernstein2 dv = scallop::derivativeV(p);
      ASSERT_EQ(du.degreeU, std::max(m - 1, 0));
      ASSERT_EQ(du.degreeV, n);
      ASSERT_EQ(dv.degreeU, m);
      ASSERT_EQ(dv.degreeV, std::max(n - 1, 0));
      for (int k = 0; k < 20; ++k) {
        const double u = randomUnit(rng);
        const double v = randomUnit(rng);
        Real refU = 0, magU = 0, refV = 0, magV = 0;
        for (int i = 0; i <= m; ++i) {
          for (int j = 0; j <= n; ++j) {
            const Real c = p.at(i, j);
            if (m > 0) {
              const Real bu = m * (basisL(m - 1, i - 1, u) - basisL(m - 1, i, u));
              refU += c * bu * basisL(n, j, v);
              magU += std::fabs(c) * m * (basisL(m - 1, i - 1, u) + basisL(m - 1, i, u)) *
                      basisL(n, j, v);
            }
            if (n > 0) {
              const Real bv = n * (basisL(n - 1, j - 1, v) - basisL(n - 1, j, v));
              refV += c * basisL(m, i, u) * bv;
              magV += std::fabs(c) * basisL(m, i, u) * n *
                      (basisL(n - 1, j - 1, v) + basisL(n - 1, j, v));
            }
          }
        }
        const Real tolU =
            gamma(3 * (m + n)) * explicitSum2(du, u, v, true) + kRefFactor2(m, n) * magU;
        const Real tolV =
            gamma(3 * (m + n)) * explicitSum2(dv, u, v, true) + kRefFactor2(m, n) * magV;
        ASSERT_LE(std::fabs(evaluate(du, u, v) - refU), tolU);
        ASSERT_LE(std::fabs(evaluate(dv, u, v) - refV), tolV);
      }
    }
  }
}

TEST(Bernstein2Multiply, MatchesPointwiseProduct) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 300; ++trial) {
    const int m1 = trial % 5, n1 = (trial / 5) % 5, m2 = (trial / 25) % 4, n2 = (trial / 100) % 4;
    const Bernstein2 p = randomBernstein2(rng, m1, n1);
    const Bernstein2 q = randomBernstein2(rng, m2, n2);
    const Bernstein2 r = scallop::multiply(p, q);
    ASSERT_EQ(r.degreeU, m1 + m2);
    ASSERT_EQ(r.degreeV, n1 + n2);
    for (int k = 0; k < 10; ++k) {
      const double u = randomUnit(rng);
      const double v = randomUnit(rng);
      // Contract (bivariate product): each term w_u w_v a b rounds 9 times' worth (two
      // weights of 3, three products), and a coefficient sums K = (min(m1,m2) + 1)
      // (min(n1,n2) + 1) terms: gamma(K + 9) Pbar Qbar; evaluation gamma(3(M + N)).
      const int terms = (std::min(m1, m2) + 1) * (std::min(n1, n2) + 1) + 9;
      const int degrees = m1 + m2 + n1 + n2;
      const Real scale = explicitSum2(p, u, v, true) * explicitSum2(q, u, v, true);
      const Real tolerance = (gamma(terms) + gamma(3 * degrees) * (1 + gamma(terms)) +
                              kRefFactor2(m1, n1) + kRefFactor2(m2, n2)) *
                             scale;
      ASSERT_LE(std::fabs(evaluate(r, u, v) - explicitSum2(p, u, v) * explicitSum2(q, u, v)),
                tolerance);
    }
  }
}

TEST(Bernstein2Add, ElevationSumsAndScale) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 300; ++trial) {
    const int m1 = trial % 5, n1 = (trial / 5) % 5, m2 = (trial / 25) % 4, n2 = (trial / 100) % 4;
    const Bernstein2 p = randomBernstein2(rng, m1, n1);
    const Bernstein2 q = randomBernstein2(rng, m2, n2);
    const Bernstein2 sum = scallop::add(p, q);
    const Bernstein2 difference = scallop::subtract(p, q);
    const Bernstein2 elevated = scallop::elevate(p, 2, 3);
    const int m = std::max(m1, m2), n = std::max(n1, n2);
    ASSERT_EQ(sum.degreeU, m);
    ASSERT_EQ(sum.degreeV, n);
    ASSERT_EQ(elevated.degreeU, m1 + 2);
    ASSERT_EQ(elevated.degreeV, n1 + 3);
    const Bernstein2 doubled = scallop::scale(p, 2.0);
    for (std::size_t i = 0; i < p.coefficients.size(); ++i) {
      ASSERT_EQ(doubled.coefficients[i], 2.0 * p.coefficients[i]);
    }
    for (int k = 0; k < 10; ++k) {
      const double u = randomUnit(rng);
      const double v = randomUnit(rng);
      // Elevation along u then v: gamma(min + 4) twice (<= gamma(2 (max(m, n) + 3) + 8));
      // one rounding for the sum; evaluation gamma(3(m + n + 5)) on the largest bidegree.
      const int elevation = 2 * (std::max(m, n) + 3) + 8;
      const Real factor = gamma(elevation) + kU +
                          gamma(3 * (m + n + 5)) * (1 + gamma(elevation + 1)) +
                          kRefFactor2(m + 2, n + 3);
      const Real pa = explicitSum2(p, u, v, true), qa = explicitSum2(q, u, v, true);
      const Real pv = explicitSum2(p, u, v), qv = explicitSum2(q, u, v);
      ASSERT_LE(std::fabs(evaluate(sum, u, v) - (pv + qv)), factor * (pa + qa));
      ASSERT_LE(std::fabs(evaluate(difference, u, v) - (pv - qv)), factor * (pa + qa));
      ASSERT_LE(std::fabs(evaluate(elevated, u, v) - pv), factor * pa);
    }
  }
}

TEST(Bernstein2Subdivide, PiecesAndRestrictionReproduceThePolynomial) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 300; ++trial) {
    const int m = trial % 7, n = (trial / 7) % 7;
    const Bernstein2 p = randomBernstein2(rng, m, n);
    const double t = randomUnit(rng);
    const auto [lu, ru] = scallop::subdivideU(p, t);
    const auto [lv, rv] = scallop::subdivideV(p, t);
    double u0 = randomUnit(rng), u1 = randomUnit(rng), v0 = randomUnit(rng), v1 = randomUnit(rng);
    if (trial % 5 == 0) std::swap(u0, u1);
    const Bernstein2 box = scallop::restrictTo(p, u0, u1, v0, v1);
    for (int k = 0; k < 10; ++k) {
      const double s = randomUnit(rng);
      const double r = randomUnit(rng);
      // Subdivision along one variable: gamma(3 max(m, n)) on the coefficients, evaluation
      // gamma(3(m + n)); restriction: gamma(6m) + gamma(6n) and the moved interval ends
      // (3u (2|a| + |b|) each way) times max|dp/du| <= 2m max|c|, max|dp/dv| <= 2n max|c|.
      const Real factor = gamma(3 * std::max(m, n)) +
                          gamma(3 * (m + n)) * (1 + gamma(3 * std::max(m, n))) + kRefFactor2(m, n);
      const Real ts = static_cast<Real>(t) * s;
      const Real te = t + (1 - static_cast<Real>(t)) * s;
      ASSERT_LE(std::fabs(evaluate(lu, s, r) - explicitSum2(p, ts, r)),
                factor * explicitSum2(p, ts, r, true));
      ASSERT_LE(std::fabs(evaluate(ru, s, r) - explicitSum2(p, te, r)),
                factor * explicitSum2(p, te, r, true));
      ASSERT_LE(std::fabs(evaluate(lv, r, s) - explicitSum2(p, r, ts)),
                factor * explicitSum2(p, r, ts, true));
      ASSERT_LE(std::fabs(evaluate(rv, r, s) - explicitSum2(p, r, te)),
                factor * explicitSum2(p, r, te, true));
      const Real x = u0 + (static_cast<Real>(u1) - u0) * s;
      const Real y = v0 + (static_cast<Real>(v1) - v0) * r;
      const Real cmax = maxAbs(p.coefficients);
      const Real boxFactor = gamma(6 * m) + gamma(6 * n) +
                             gamma(3 * (m + n)) * (1 + gamma(6 * (m + n))) + kRefFactor2(m, n);
      const Real moved = 2 * cmax * 3 * kU * (m * (2 * u0 + u1) + n * (2 * v0 + v1));
      ASSERT_LE(std::fabs(evaluate(box, s, r) - explicitSum2(p, x, y)),
                boxFactor * explicitSum2(p, x, y, true) * (1 + gamma(6 * m)) + moved);
    }
  }
}

TEST(Bernstein2Bounds, BoundsMayVanishAndIsoLines) {
  std::mt19937_64 rng(42);
  for (int trial = 0; trial < 300; ++trial) {
    const int m = trial % 6, n = (trial / 6) % 6;
    Bernstein2 p = randomBernstein2(rng, m, n);
    if (trial % 3 == 0) {
      for (double& c : p.coefficients) c = std::fabs(c) + 0.01;  // strictly positive
    }
    const scallop::Bounds b = scallop::bounds(p);
    const bool positive = b.lo > 0.0;
    ASSERT_EQ(scallop::mayVanish(p), !(b.lo > 0.0 || b.hi < 0.0));
    for (int k = 0; k < 10; ++k) {
      const double u = randomUnit(rng);
      const double v = randomUnit(rng);
      const double tolerance =
          gamma(3 * (m + n)) * static_cast<double>(explicitSum2(p, u, v, true));
      const double value = evaluate(p, u, v);
      ASSERT_GE(value, b.lo - tolerance);
      ASSERT_LE(value, b.hi + tolerance);
      if (positive) {
        ASSERT_GT(explicitSum2(p, u, v), 0);
      }
      // Iso-lines: columns evaluated at u0 (isoU), rows at v0 (isoV); the values agree with
      // evaluate up to both evaluation errors, gamma(3(m + n)) Pbar each.
      const Bernstein1 alongV = scallop::isoU(p, u);
      const Bernstein1 alongU = scallop::isoV(p, v);
      ASSERT_EQ(alongV.degree(), n);
      ASSERT_EQ(alongU.degree(), m);
      const double twice = 2 * tolerance;
      ASSERT_NEAR(evaluate(alongV, v), value, twice);
      ASSERT_NEAR(evaluate(alongU, u), value, twice);
    }
  }
  EXPECT_TRUE(scallop::mayVanish(Bernstein2{1, 1, {1.0, 0.0, 2.0, 3.0}}));  // a zero coefficient
  EXPECT_FALSE(scallop::mayVanish(Bernstein2{1, 1, {-1.0, -0.5, -2.0, -3.0}}));
  EXPECT_TRUE(scallop::mayVanish(Bernstein2{0, 0, {0.0}}));
  // Boundary lines are exact: isoU(p, 0) is the first row, isoV(p, 1) the last column.
  const Bernstein2 p{1, 2, {1.0, 2.0, 3.0, 4.0, 5.0, 6.0}};
  EXPECT_EQ(scallop::isoU(p, 0.0).coefficients, (std::vector<double>{1.0, 2.0, 3.0}));
  EXPECT_EQ(scallop::isoV(p, 1.0).coefficients, (std::vector<double>{3.0, 6.0}));
}

}  // namespace

// divideEdgeFactors against multiplication: q times u^a (1 - u)^b v^c (1 - v)^d (built by
// Bernstein products of the linear factors), divided, gives q back and the exponents; the
// quotient agrees with p / factors pointwise inside the square. A polynomial with no factor
// comes back unchanged, and the zero polynomial stops at degree 0.
TEST(BernsteinEdgeFactors, DivisionUndoesMultiplication) {
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<int> power(0, 2);
  const Bernstein2 u{1, 0, {0.0, 1.0}}, oneMinusU{1, 0, {1.0, 0.0}};
  const Bernstein2 v{0, 1, {0.0, 1.0}}, oneMinusV{0, 1, {1.0, 0.0}};
  for (int trial = 0; trial < 400; ++trial) {
    const int m = 1 + trial % 5, n = 1 + (trial / 5) % 5;
    Bernstein2 q = randomBernstein2(rng, m, n);
    // Keep q's own edges away from zero so that no further factor divides it.
    for (double& c : q.coefficients) c = c >= 0.0 ? c + 0.5 : c - 0.5;
    const scallop::EdgePowers want{power(rng), power(rng), power(rng), power(rng)};
    Bernstein2 p = q;
    for (int i = 0; i < want.u0; ++i) p = scallop::multiply(p, u);
    for (int i = 0; i < want.u1; ++i) p = scallop::multiply(p, oneMinusU);
    for (int i = 0; i < want.v0; ++i) p = scallop::multiply(p, v);
    for (int i = 0; i < want.v1; ++i) p = scallop::multiply(p, oneMinusV);
    scallop::EdgePowers got;
    const Bernstein2 quotient = scallop::divideEdgeFactors({p}, 1e-13, got).front();
    // Edge rows of p built by multiplication are exact zeros, and q's are not small: the
    // exponents are exact.
    EXPECT_EQ(got.u0, want.u0) << trial;
    EXPECT_EQ(got.u1, want.u1) << trial;
    EXPECT_EQ(got.v0, want.v0) << trial;
    EXPECT_EQ(got.v1, want.v1) << trial;
    ASSERT_EQ(quotient.degreeU, q.degreeU);
    ASSERT_EQ(quotient.degreeV, q.degreeV);
    for (int s = 0; s < 10; ++s) {
      const double a = 0.05 + 0.9 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      const double b = 0.05 + 0.9 * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      const double expected = scallop::evaluate(q, a, b);
      EXPECT_NEAR(scallop::evaluate(quotient, a, b), expected, 1e-12 * (1.0 + std::abs(expected)));
      EXPECT_NEAR(scallop::evaluate(p, a, b) / got.at(a, b), expected, 1e-9 * (1.0 + std::abs(expected)));
    }
  }
  // Nothing to divide.
  std::mt19937_64 rng2(3);
  Bernstein2 plain = randomBernstein2(rng2, 3, 4);
  for (double& c : plain.coefficients) c += 5.0;
  scallop::EdgePowers none;
  EXPECT_EQ(scallop::divideEdgeFactors({plain}, 1e-13, none).front().coefficients, plain.coefficients);
  EXPECT_FALSE(none.any());
  // Zero: every edge vanishes; degrees stop at 0.
  const Bernstein2 zero{3, 2, std::vector<double>(12, 0.0)};
  scallop::EdgePowers all;
  const Bernstein2 rest = scallop::divideEdgeFactors({zero}, 0.0, all).front();
  EXPECT_EQ(rest.degreeU, 0);
  EXPECT_EQ(rest.degreeV, 0);
  // Polynomials of different bidegrees are refused.
  EXPECT_THROW(scallop::divideEdgeFactors({zero, plain}, 0.0, all), scallop::Error);
}
