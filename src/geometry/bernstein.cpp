// Polynomials in Bernstein form: de Casteljau evaluation and subdivision, products, degree
// elevation, tensor products, and certified real-root isolation on [0, 1].
// See include/scallop/bernstein.hpp for the contract and the error bounds.

#include "scallop/geometry/bernstein.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <fmt/format.h>

#include "scallop/error.hpp"
#include "scallop/geometry/tolerances.hpp"

namespace scallop {
namespace {

// Running error bounds are themselves computed in floating point; scaling the propagated
// part by (1 + 4u) per step and adding the smallest subnormal (the absolute error of halving
// a subnormal) keeps them upper bounds despite their own rounding.
constexpr double kGrow = 1.0 + 4 * kUnitRoundoff;
constexpr double kTiny = std::numeric_limits<double>::denorm_min();
// Safeguarded Newton: each iteration at least halves the bracket every second step, so 200
// iterations cover the 2 x 64 halvings from width 1 to adjacent doubles with room to spare.
constexpr int kMaxRefineIterations = 200;
// Small-buffer size for evaluation without allocation (degrees up to 31).
constexpr std::size_t kSmallBuffer = 32;

// ---------------------------------------------------------------------------------------
// Validation
// ---------------------------------------------------------------------------------------

void requireValid(const Bernstein1& p, const char* what) {
  if (p.coefficients.empty()) {
    throw Error(fmt::format("{}: a Bernstein polynomial needs at least one coefficient", what));
  }
}

void requireValid(const Bernstein2& p, const char* what) {
  if (p.degreeU < 0 || p.degreeV < 0) {
    throw Error(fmt::format("{}: negative bidegree ({}, {})", what, p.degreeU, p.degreeV));
  }
  const std::size_t expected =
      static_cast<std::size_t>(p.degreeU + 1) * static_cast<std::size_t>(p.degreeV + 1);
  if (p.coefficients.size() != expected) {
    throw Error(fmt::format("{}: bidegree ({}, {}) needs {} coefficients, got {}", what, p.degreeU,
                            p.degreeV, expected, p.coefficients.size()));
  }
}

void requireDegree(long long degree, const char* what) {
  if (degree > kMaxBernsteinDegree) {
    throw Error(fmt::format("{}: degree {} exceeds kMaxBernsteinDegree = {}", what, degree,
                            kMaxBernsteinDegree));
  }
}

// ---------------------------------------------------------------------------------------
// Univariate kernels on coefficient vectors (shared by Bernstein1 and the rows/columns of
// Bernstein2)
// ---------------------------------------------------------------------------------------

using Coefficients = std::vector<double>;

// C(n, 0) .. C(n, n) by C(n, k) = C(n, k - 1) (n - k + 1) / k: in 64-bit integers for
// n <= 62 (the largest intermediate, C(62, 30) * 32 ~ 1.5e19, fits), hence exact in double
// for n <= 56 (C(56, 28) < 2^53) and correctly rounded up to 62; in double beyond (relative
// error <= n u).
Coefficients binomialRow(int n) {
  Coefficients row(n + 1, 1.0);
  if (n <= 62) {
    std::uint64_t c = 1;
    for (int k = 1; k <= n / 2; ++k) {
      c = c * static_cast<std::uint64_t>(n - k + 1) / static_cast<std::uint64_t>(k);
      row[k] = row[n - k] = static_cast<double>(c);
    }
  } else {
    double c = 1.0;
    for (int k = 1; k <= n / 2; ++k) {
      c = c * (n - k + 1) / k;
      row[k] = row[n - k] = c;
    }
  }
  return row;
}

// Weights of the Bernstein product: w[i (n + 1) + j] = C(m, i) C(n, j) / C(m + n, i + j).
// The numerator never exceeds the denominator (Vandermonde), so nothing overflows while
// C(m + n, .) is finite.
Coefficients productWeights(int m, int n) {
  const Coefficients rm = binomialRow(m);
  const Coefficients rn = binomialRow(n);
  const Coefficients rmn = binomialRow(m + n);
  Coefficients w(static_cast<std::size_t>(m + 1) * static_cast<std::size_t>(n + 1));
  for (int i = 0; i <= m; ++i) {
    for (int j = 0; j <= n; ++j) w[i * (n + 1) + j] = rm[i] * rn[j] / rmn[i + j];
  }
  return w;
}

int degreeOf(const Coefficients& c) { return static_cast<int>(c.size()) - 1; }

Coefficients multiplyCoefficients(const Coefficients& a, const Coefficients& b) {
  const int m = degreeOf(a);
  const int n = degreeOf(b);
  const Coefficients w = productWeights(m, n);
  Coefficients r(m + n + 1, 0.0);
  for (int i = 0; i <= m; ++i) {
    for (int j = 0; j <= n; ++j) r[i + j] += w[i * (n + 1) + j] * a[i] * b[j];
  }
  return r;
}

// Degree elevation by `times`: the product with 1 = sum_i b_i^times, i.e. the convex
// combination c'_k = sum_j C(n, j) C(r, k - j) / C(n + r, k) c_j.
Coefficients elevateCoefficients(const Coefficients& c, int times) {
  if (times == 0) return c;
  const int n = degreeOf(c);
  const Coefficients w = productWeights(n, times);
  Coefficients r(n + times + 1, 0.0);
  for (int j = 0; j <= n; ++j) {
    for (int k = 0; k <= times; ++k) r[j + k] += w[j * (times + 1) + k] * c[j];
  }
  return r;
}

Coefficients derivativeCoefficients(const Coefficients& c) {
  const int n = degreeOf(c);
  if (n == 0) return {0.0};
  Coefficients d(n);
  for (int i = 0; i < n; ++i) d[i] = n * (c[i + 1] - c[i]);
  return d;
}

// In-place de Casteljau on b[0 .. n]; returns p(t).
double deCasteljau(double* b, int n, double t) {
  const double s = 1.0 - t;
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i <= n - r; ++i) b[i] = s * b[i] + t * b[i + 1];
  }
  return b[0];
}

double evaluateCoefficients(const Coefficients& c, double t) {
  std::array<double, kSmallBuffer> small{};
  Coefficients large;
  double* b = small.data();
  if (c.size() <= kSmallBuffer) {
    std::copy(c.begin(), c.end(), small.begin());
  } else {
    large = c;
    b = large.data();
  }
  return deCasteljau(b, degreeOf(c), t);
}

// De Casteljau subdivision at t: left(s) = p(t s), right(s) = p(t + (1 - t) s).
void splitCoefficients(const Coefficients& c, double t, Coefficients* left, Coefficients* right) {
  const int n = degreeOf(c);
  const double s = 1.0 - t;
  Coefficients b = c;
  if (left != nullptr) {
    left->assign(n + 1, 0.0);
    (*left)[0] = b[0];
  }
  if (right != nullptr) {
    right->assign(n + 1, 0.0);
    (*right)[n] = b[n];
  }
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i <= n - r; ++i) b[i] = s * b[i] + t * b[i + 1];
    if (left != nullptr) (*left)[r] = b[0];
    if (right != nullptr) (*right)[n - r] = b[n - r];
  }
}

Coefficients leftPart(const Coefficients& c, double t) {
  Coefficients left;
  splitCoefficients(c, t, &left, nullptr);
  return left;
}

Coefficients rightPart(const Coefficients& c, double t) {
  Coefficients right;
  splitCoefficients(c, t, nullptr, &right);
  return right;
}

// q(s) = p(a + (b - a) s). For a > b, the reversal of p on [b, a]. For a <= b, two
// subdivisions; the one dividing by the larger of |b| and |1 - a| is used (>= 1/2 when a, b
// lie in [0, 1], and then both parameters lie in [0, 1]: convex combinations only):
//   |b| >= |1 - a|: L = p on [0, b], then L on [a / b, 1];
//   otherwise:      R = p on [a, 1], then R on [0, (b - a) / (1 - a)].
Coefficients restrictCoefficients(const Coefficients& c, double a, double b) {
  if (a > b) {
    const Coefficients reversed = restrictCoefficients(c, b, a);
    return Coefficients(reversed.rbegin(), reversed.rend());
  }
  if (std::abs(b) >= std::abs(1.0 - a)) {
    if (b == 0.0) return Coefficients(c.rbegin(), c.rend());  // a = 1, b = 0: p(1 - s)
    return rightPart(leftPart(c, b), a / b);
  }
  return leftPart(rightPart(c, a), (b - a) / (1.0 - a));
}

// ---------------------------------------------------------------------------------------
// Coefficients with running error bounds, for root isolation
// ---------------------------------------------------------------------------------------

// c[i] approximates the exact coefficient of some polynomial of the family within e[i].
struct Tracked {
  Coefficients c;
  Coefficients e;
};

// De Casteljau at 1/2: v = a / 2 + b / 2 rounds once (|error| <= u |v|; halving is exact
// but for subnormals, which kTiny covers; halving first cannot overflow), so
// e_v = (e_a + e_b) / 2 + u |v|; we charge 2u |v| for the rounding of the bound itself.
void halveTracked(const Tracked& p, Tracked& left, Tracked& right) {
  const int n = degreeOf(p.c);
  Coefficients b = p.c;
  Coefficients e = p.e;
  left.c.assign(n + 1, 0.0);
  left.e.assign(n + 1, 0.0);
  right.c.assign(n + 1, 0.0);
  right.e.assign(n + 1, 0.0);
  left.c[0] = b[0];
  left.e[0] = e[0];
  right.c[n] = b[n];
  right.e[n] = e[n];
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i <= n - r; ++i) {
      const double v = 0.5 * b[i] + 0.5 * b[i + 1];
      e[i] = 0.5 * (e[i] + e[i + 1]) * kGrow + 2 * kUnitRoundoff * std::abs(v) + kTiny;
      b[i] = v;
    }
    left.c[r] = b[0];
    left.e[r] = e[0];
    right.c[n - r] = b[n - r];
    right.e[n - r] = e[n - r];
  }
}

// One part of the de Casteljau subdivision at t in [0, 1], with error bounds:
// v = fl(fl(1 - t) x + t y) is off by <= 3u (s|x| + t|y|) (1 - t, two products, one sum);
// we charge 4u.
Tracked splitTracked(const Tracked& p, double t, bool wantLeft) {
  const int n = degreeOf(p.c);
  const double s = 1.0 - t;
  Coefficients b = p.c;
  Coefficients e = p.e;
  Tracked out{Coefficients(n + 1, 0.0), Coefficients(n + 1, 0.0)};
  const int first = wantLeft ? 0 : n;
  out.c[first] = b[first];
  out.e[first] = e[first];
  for (int r = 1; r <= n; ++r) {
    for (int i = 0; i <= n - r; ++i) {
      e[i] = (s * e[i] + t * e[i + 1]) * kGrow +
             4 * kUnitRoundoff * (s * std::abs(b[i]) + t * std::abs(b[i + 1])) + kTiny;
      b[i] = s * b[i] + t * b[i + 1];
    }
    const int k = wantLeft ? 0 : n - r;
    out.c[wantLeft ? r : n - r] = b[k];
    out.e[wantLeft ? r : n - r] = e[k];
  }
  return out;
}

// Coefficients on an interval J' containing [a, b] (0 <= a < b <= 1), J' wider than [a, b]
// by a few ulps: the division's rounding is pushed outward so that a sign proved on J' holds
// on all of [a, b].
Tracked restrictTracked(const Tracked& p, double a, double b) {
  constexpr double kOutward = 8 * kUnitRoundoff;
  if (b >= 1.0 - a) {
    const Tracked left = splitTracked(p, b, true);
    return splitTracked(left, (a / b) * (1.0 - kOutward), false);
  }
  const Tracked right = splitTracked(p, a, false);
  return splitTracked(right, std::min(1.0, (b - a) / (1.0 - a) * (1.0 + kOutward)), true);
}

// d_i = n (c_{i+1} - c_i): the difference and the product by n round once each.
Tracked derivativeTracked(const Tracked& p) {
  const int n = degreeOf(p.c);
  if (n == 0) return {{0.0}, {0.0}};
  Tracked d{Coefficients(n), Coefficients(n)};
  for (int i = 0; i < n; ++i) {
    d.c[i] = n * (p.c[i + 1] - p.c[i]);
    d.e[i] = n * (p.e[i] + p.e[i + 1]) * kGrow + 3 * kUnitRoundoff * std::abs(d.c[i]) + kTiny;
  }
  return d;
}

// +1 / -1 when the sign of the exact coefficient is certain, 0 otherwise.
int certainSign(double c, double e) { return c > e ? 1 : (c < -e ? -1 : 0); }

bool provablyOneSign(const Tracked& p) {
  const int s0 = certainSign(p.c[0], p.e[0]);
  if (s0 == 0) return false;
  for (std::size_t i = 1; i < p.c.size(); ++i) {
    if (certainSign(p.c[i], p.e[i]) != s0) return false;
  }
  return true;
}

// True when every polynomial of the family shows exactly one sign variation: certain signs
// s0 .. s0 then -s0 .. -s0, with at most one uncertain coefficient between the two runs
// (two could hide a variation -s0, s0 and give three).
bool provablyOneVariation(const std::vector<int>& signs) {
  const int n = static_cast<int>(signs.size()) - 1;
  const int s0 = signs[0];
  if (s0 == 0 || signs[n] != -s0) return false;
  int i = 0;
  while (i <= n && signs[i] == s0) ++i;
  int j = n;
  while (j >= 0 && signs[j] == -s0) --j;
  // signs[i .. j] must be uncertain and at most one of them.
  return j - i + 1 <= 1 && (j < i || signs[i] == 0);
}

// The largest number of sign variations any member of the family can show: an uncertain
// coefficient may take either sign or vanish. Dynamic programming over the last sign.
int maxVariations(const Tracked& p) {
  constexpr int kNone = -1;
  int endPositive = kNone;  // most variations of a prefix whose last nonzero sign is +
  int endNegative = kNone;
  bool noSignYet = true;
  for (std::size_t i = 0; i < p.c.size(); ++i) {
    const int s = certainSign(p.c[i], p.e[i]);
    const int start = noSignYet ? 0 : kNone;
    const int toPositive =
        std::max({endPositive, endNegative == kNone ? kNone : endNegative + 1, start});
    const int toNegative =
        std::max({endNegative, endPositive == kNone ? kNone : endPositive + 1, start});
    if (s > 0) {
      endPositive = toPositive;
      endNegative = kNone;
      noSignYet = false;
    } else if (s < 0) {
      endNegative = toNegative;
      endPositive = kNone;
      noSignYet = false;
    } else {
      endPositive = toPositive;
      endNegative = toNegative;
    }
  }
  return std::max({endPositive, endNegative, 0});
}

// A leaf of the bisection: a certified simple root or an unresolved interval, with the
// certified signs of the polynomial at its ends (0 when uncertain).
struct Leaf {
  double lo = 0.0;
  double hi = 0.0;
  bool simple = false;
  int signLo = 0;
  int signHi = 0;
};

void isolateRecursive(const Tracked& p, double lo, double hi, int depth, const RootOptions& options,
                      std::vector<Leaf>& leaves) {
  if (provablyOneSign(p)) return;
  const int n = degreeOf(p.c);
  std::vector<int> signs(n + 1);
  bool allUncertain = true;
  for (int i = 0; i <= n; ++i) {
    signs[i] = certainSign(p.c[i], p.e[i]);
    if (signs[i] != 0) allUncertain = false;
  }
  if (provablyOneVariation(signs)) {
    leaves.push_back({lo, hi, true, signs[0], signs[n]});
    return;
  }
  const double mid = lo + 0.5 * (hi - lo);  // exact: lo, hi are dyadic
  const bool canSplit = !allUncertain && hi - lo > options.resolution && depth < options.maxDepth &&
                        mid > lo && mid < hi;
  if (!canSplit) {
    leaves.push_back({lo, hi, false, signs[0], signs[n]});
    return;
  }
  Tracked left;
  Tracked right;
  halveTracked(p, left, right);
  isolateRecursive(left, lo, mid, depth + 1, options, leaves);
  isolateRecursive(right, mid, hi, depth + 1, options, leaves);
}

// Upper bound on the roots (with multiplicity) in the open interval (a, b): the smallest k
// whose k-th derivative is provably of one sign on [a, b] (by Rolle's theorem p then has at
// most k roots there), capped by the largest possible sign variation count of p on [a, b].
int rootCountBound(const Tracked& p, double a, double b) {
  const int n = degreeOf(p.c);
  const Tracked local = restrictTracked(p, a, b);
  if (provablyOneSign(local)) return 0;
  const int variations = maxVariations(local);
  Tracked d = p;
  for (int k = 1; k <= n; ++k) {
    d = derivativeTracked(d);
    if (provablyOneSign(restrictTracked(d, a, b))) return std::min(k, variations);
  }
  return std::min(n, variations);
}

struct DetailedRoot {
  RootInterval interval;
  int signLo = 0;  // certified sign of the deflated polynomial at interval.lo (simple roots)
};

struct Isolation {
  std::vector<DetailedRoot> roots;
  Bernstein1 deflated;  // p / (t^k0 (1 - t)^k1): no exact roots at 0 and 1
  bool zero = false;
};

void requireFiniteOptions(const Bernstein1& p, const RootOptions& options, const char* what) {
  requireValid(p, what);
  for (std::size_t i = 0; i < p.coefficients.size(); ++i) {
    if (!std::isfinite(p.coefficients[i])) {
      throw Error(fmt::format("{}: coefficient {} is not finite ({})", what, i, p.coefficients[i]));
    }
  }
  if (!(options.resolution >= 0.0) || !std::isfinite(options.resolution)) {
    throw Error(
        fmt::format("{}: resolution must be finite and >= 0, got {}", what, options.resolution));
  }
  if (options.maxDepth < 0) {
    throw Error(fmt::format("{}: maxDepth must be >= 0, got {}", what, options.maxDepth));
  }
}

Isolation isolate(const Bernstein1& p, const RootOptions& options, const char* what) {
  requireFiniteOptions(p, options, what);
  Isolation result;
  const Coefficients& c = p.coefficients;
  const int n = p.degree();
  if (isZero(p)) {
    result.zero = true;
    result.roots.push_back({{0.0, 1.0, 0, true}, 0});
    result.deflated = p;
    return result;
  }
  // Exact roots at the ends: c_0 = p(0), and c_0 = .. = c_{k-1} = 0 iff p, p', .., p^(k-1)
  // vanish at 0 (p^(j)(0) = n!/(n-j)! times the j-th forward difference of c_0 .. c_j).
  int k0 = 0;
  while (c[k0] == 0.0) ++k0;
  int k1 = 0;
  while (c[n - k1] == 0.0) ++k1;
  // Deflate: t^k0 (1 - t)^k1 b_j^m(t) = C(m, j) / C(n, j + k0) b_{j+k0}^n(t), m = n - k0 - k1.
  const int m = n - k0 - k1;
  Tracked q{Coefficients(m + 1), Coefficients(m + 1)};
  if (k0 == 0 && k1 == 0) {
    q.c = c;
    for (int i = 0; i <= n; ++i) q.e[i] = kUnitRoundoff * std::abs(c[i]);  // input rounding
  } else {
    const Coefficients rn = binomialRow(n);
    const Coefficients rm = binomialRow(m);
    // Input rounding (u), the ratio of two binomials and one product (2u), and the
    // binomials themselves beyond degree 56 (n u); charged as (4 + n) u.
    const double relative = (4.0 + (n > 56 ? n : 0)) * kUnitRoundoff;
    for (int j = 0; j <= m; ++j) {
      q.c[j] = c[j + k0] * (rn[j + k0] / rm[j]);
      q.e[j] = relative * std::abs(q.c[j]);
    }
  }
  result.deflated.coefficients = q.c;

  if (k0 > 0) result.roots.push_back({{0.0, 0.0, k0, k0 > 1}, 0});
  if (m > 0) {
    std::vector<Leaf> leaves;
    isolateRecursive(q, 0.0, 1.0, 0, options, leaves);
    for (std::size_t i = 0; i < leaves.size();) {
      const Leaf& leaf = leaves[i];
      if (leaf.simple) {
        result.roots.push_back({{leaf.lo, leaf.hi, 1, false}, leaf.signLo});
        ++i;
        continue;
      }
      // Merge a run of adjacent unresolved leaves into J = [lo, hi].
      std::size_t last = i;
      while (last + 1 < leaves.size() && !leaves[last + 1].simple &&
             leaves[last + 1].lo == leaves[last].hi) {
        ++last;
      }
      const double lo = leaf.lo;
      const double hi = leaves[last].hi;
      const int signLo = leaf.signLo;
      const int signHi = leaves[last].signHi;
      i = last + 1;
      const int bound = rootCountBound(q, lo, hi);
      int count = bound;
      const bool parityKnown = signLo != 0 && signHi != 0;
      if (parityKnown) {
        const int parity = signLo != signHi ? 1 : 0;
        if (count % 2 != parity) --count;
      }
      if (count <= 0) continue;  // provably no root (bound 0, or bound 1 with even parity)
      const bool provedSimple = parityKnown && count == 1 && bound <= 2;
      result.roots.push_back({{lo, hi, count, !provedSimple}, signLo});
    }
  }
  if (k1 > 0) result.roots.push_back({{1.0, 1.0, k1, k1 > 1}, 0});
  return result;
}

// Safeguarded Newton on a bracket [lo, hi] with sign(q(lo)) = signLo = -sign(q(hi))
// (Numerical Recipes' rtsafe): Newton while it stays inside the bracket and at least halves
// the step before last, bisection otherwise; the bracket shrinks at every evaluation.
double refineSimpleRoot(const Bernstein1& q, const Bernstein1& dq, double lo, double hi,
                        int signLo) {
  double a = lo;
  double b = hi;
  double x = a + 0.5 * (b - a);
  double stepBefore = b - a;
  double step = stepBefore;
  for (int iteration = 0; iteration < kMaxRefineIterations; ++iteration) {
    const double f = evaluate(q, x);
    if (f == 0.0) return x;
    if ((f > 0.0) == (signLo > 0)) {
      a = x;
    } else {
      b = x;
    }
    if (b - a <= 2 * kUnitRoundoff * std::max(std::abs(a), std::abs(b))) break;
    const double df = evaluate(dq, x);
    double next = df != 0.0 ? x - f / df : a;
    const bool newton =
        df != 0.0 && next > a && next < b && std::abs(2.0 * f) <= std::abs(stepBefore * df);
    stepBefore = step;
    if (newton) {
      step = std::abs(next - x);
    } else {
      next = a + 0.5 * (b - a);
      step = 0.5 * (b - a);
    }
    if (next == x) break;
    x = next;
  }
  return x;
}

// ---------------------------------------------------------------------------------------
// Tensor-product helpers: apply a univariate operation along u (columns) or v (rows)
// ---------------------------------------------------------------------------------------

Coefficients columnOf(const Bernstein2& p, int j) {  // c_0j .. c_mj, a polynomial in u
  Coefficients column(p.degreeU + 1);
  for (int i = 0; i <= p.degreeU; ++i) column[i] = p.at(i, j);
  return column;
}

Coefficients rowOf(const Bernstein2& p, int i) {  // c_i0 .. c_in, a polynomial in v
  const auto first = p.coefficients.begin() + i * (p.degreeV + 1);
  return Coefficients(first, first + (p.degreeV + 1));
}

Bernstein2 zero2(int degreeU, int degreeV) {
  return {degreeU, degreeV,
          Coefficients(
              static_cast<std::size_t>(degreeU + 1) * static_cast<std::size_t>(degreeV + 1), 0.0)};
}

// Applies f (coefficients in u of degree m -> coefficients of degree newDegreeU) to every column.
template <class F>
Bernstein2 mapColumns(const Bernstein2& p, int newDegreeU, F f) {
  Bernstein2 r = zero2(newDegreeU, p.degreeV);
  for (int j = 0; j <= p.degreeV; ++j) {
    const Coefficients column = f(columnOf(p, j));
    for (int i = 0; i <= newDegreeU; ++i) r.coefficients[i * (p.degreeV + 1) + j] = column[i];
  }
  return r;
}

// Applies f (coefficients in v of degree n -> coefficients of degree newDegreeV) to every row.
template <class F>
Bernstein2 mapRows(const Bernstein2& p, int newDegreeV, F f) {
  Bernstein2 r = zero2(p.degreeU, newDegreeV);
  for (int i = 0; i <= p.degreeU; ++i) {
    const Coefficients row = f(rowOf(p, i));
    std::copy(row.begin(), row.end(), r.coefficients.begin() + i * (newDegreeV + 1));
  }
  return r;
}

Bernstein2 combine(const Bernstein2& p, const Bernstein2& q, double sign, const char* what) {
  requireValid(p, what);
  requireValid(q, what);
  const int m = std::max(p.degreeU, q.degreeU);
  const int n = std::max(p.degreeV, q.degreeV);
  const Bernstein2 a = elevate(p, m - p.degreeU, n - p.degreeV);
  const Bernstein2 b = elevate(q, m - q.degreeU, n - q.degreeV);
  Bernstein2 r = a;
  for (std::size_t k = 0; k < r.coefficients.size(); ++k) {
    r.coefficients[k] = a.coefficients[k] + sign * b.coefficients[k];
  }
  return r;
}

Bernstein1 combine(const Bernstein1& p, const Bernstein1& q, double sign, const char* what) {
  requireValid(p, what);
  requireValid(q, what);
  const int n = std::max(p.degree(), q.degree());
  const Coefficients a = elevateCoefficients(p.coefficients, n - p.degree());
  const Coefficients b = elevateCoefficients(q.coefficients, n - q.degree());
  Bernstein1 r{a};
  for (int k = 0; k <= n; ++k) r.coefficients[k] = a[k] + sign * b[k];
  return r;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Bernstein1
// ---------------------------------------------------------------------------------------

double evaluate(const Bernstein1& p, double t) {
  requireValid(p, "evaluate");
  return evaluateCoefficients(p.coefficients, t);
}

Bernstein1 derivative(const Bernstein1& p) {
  requireValid(p, "derivative");
  return {derivativeCoefficients(p.coefficients)};
}

Bernstein1 multiply(const Bernstein1& p, const Bernstein1& q) {
  requireValid(p, "multiply");
  requireValid(q, "multiply");
  requireDegree(static_cast<long long>(p.degree()) + q.degree(), "multiply");
  return {multiplyCoefficients(p.coefficients, q.coefficients)};
}

Bernstein1 add(const Bernstein1& p, const Bernstein1& q) { return combine(p, q, 1.0, "add"); }

Bernstein1 subtract(const Bernstein1& p, const Bernstein1& q) {
  return combine(p, q, -1.0, "subtract");
}

Bernstein1 scale(const Bernstein1& p, double s) {
  requireValid(p, "scale");
  Bernstein1 r = p;
  for (double& c : r.coefficients) c *= s;
  return r;
}

Bernstein1 elevate(const Bernstein1& p, int times) {
  requireValid(p, "elevate");
  if (times < 0) throw Error(fmt::format("elevate: times must be >= 0, got {}", times));
  requireDegree(static_cast<long long>(p.degree()) + times, "elevate");
  return {elevateCoefficients(p.coefficients, times)};
}

std::pair<Bernstein1, Bernstein1> subdivide(const Bernstein1& p, double t) {
  requireValid(p, "subdivide");
  std::pair<Bernstein1, Bernstein1> parts;
  splitCoefficients(p.coefficients, t, &parts.first.coefficients, &parts.second.coefficients);
  return parts;
}

Bernstein1 restrictTo(const Bernstein1& p, double a, double b) {
  requireValid(p, "restrictTo");
  return {restrictCoefficients(p.coefficients, a, b)};
}

Bernstein1 fromPowerBasis(const std::vector<double>& powerCoefficients) {
  if (powerCoefficients.empty()) {
    throw Error("fromPowerBasis: a polynomial needs at least one coefficient");
  }
  const int n = static_cast<int>(powerCoefficients.size()) - 1;
  requireDegree(n, "fromPowerBasis");
  // t^j = sum_{i >= j} C(i, j) / C(n, j) b_i^n(t), so c_i = sum_{j <= i} C(i, j) / C(n, j) a_j.
  const Coefficients rn = binomialRow(n);
  Bernstein1 p{Coefficients(n + 1, 0.0)};
  for (int i = 0; i <= n; ++i) {
    const Coefficients ri = binomialRow(i);
    double sum = 0.0;
    for (int j = 0; j <= i; ++j) sum += ri[j] / rn[j] * powerCoefficients[j];
    p.coefficients[i] = sum;
  }
  return p;
}

std::vector<double> toPowerBasis(const Bernstein1& p) {
  requireValid(p, "toPowerBasis");
  // b_i^n(t) = C(n, i) t^i (1 - t)^(n - i), so a_j = C(n, j) sum_{i <= j} (-1)^(j - i) C(j, i) c_i.
  const int n = p.degree();
  const Coefficients rn = binomialRow(n);
  std::vector<double> a(n + 1, 0.0);
  for (int j = 0; j <= n; ++j) {
    const Coefficients rj = binomialRow(j);
    double sum = 0.0;
    for (int i = 0; i <= j; ++i) {
      const double term = rj[i] * p.coefficients[i];
      sum += (j - i) % 2 == 0 ? term : -term;
    }
    a[j] = rn[j] * sum;
  }
  return a;
}

Bounds bounds(const Bernstein1& p) {
  requireValid(p, "bounds");
  const auto [lo, hi] = std::minmax_element(p.coefficients.begin(), p.coefficients.end());
  return {*lo, *hi};
}

int signVariations(const Bernstein1& p) {
  requireValid(p, "signVariations");
  int variations = 0;
  int last = 0;
  for (double c : p.coefficients) {
    const int s = c > 0.0 ? 1 : (c < 0.0 ? -1 : 0);
    if (s == 0) continue;
    if (last != 0 && s != last) ++variations;
    last = s;
  }
  return variations;
}

bool isZero(const Bernstein1& p) {
  requireValid(p, "isZero");
  return std::all_of(p.coefficients.begin(), p.coefficients.end(),
                     [](double c) { return c == 0.0; });
}

std::vector<RootInterval> isolateRoots(const Bernstein1& p, const RootOptions& options) {
  const Isolation isolation = isolate(p, options, "isolateRoots");
  std::vector<RootInterval> roots;
  roots.reserve(isolation.roots.size());
  for (const DetailedRoot& root : isolation.roots) roots.push_back(root.interval);
  return roots;
}

std::vector<double> realRoots(const Bernstein1& p, const RootOptions& options) {
  const Isolation isolation = isolate(p, options, "realRoots");
  if (isolation.zero) {
    throw Error("realRoots: the zero polynomial vanishes everywhere on [0, 1]");
  }
  const Bernstein1 dq = derivative(isolation.deflated);
  std::vector<double> roots;
  for (const DetailedRoot& root : isolation.roots) {
    const RootInterval& interval = root.interval;
    double value = interval.lo + 0.5 * (interval.hi - interval.lo);
    if (!interval.cluster && interval.lo < interval.hi) {
      value = refineSimpleRoot(isolation.deflated, dq, interval.lo, interval.hi, root.signLo);
    }
    roots.insert(roots.end(), interval.count, value);
  }
  return roots;
}

// ---------------------------------------------------------------------------------------
// Bernstein2
// ---------------------------------------------------------------------------------------

double evaluate(const Bernstein2& p, double u, double v) {
  requireValid(p, "evaluate");
  const int m = p.degreeU;
  const int n = p.degreeV;
  std::array<double, kSmallBuffer> smallRows{};
  std::array<double, kSmallBuffer> smallColumn{};
  Coefficients largeRows;
  Coefficients largeColumn;
  double* row = smallRows.data();
  double* column = smallColumn.data();
  if (static_cast<std::size_t>(n + 1) > kSmallBuffer) {
    largeRows.resize(n + 1);
    row = largeRows.data();
  }
  if (static_cast<std::size_t>(m + 1) > kSmallBuffer) {
    largeColumn.resize(m + 1);
    column = largeColumn.data();
  }
  for (int i = 0; i <= m; ++i) {
    std::copy_n(p.coefficients.begin() + i * (n + 1), n + 1, row);
    column[i] = deCasteljau(row, n, v);
  }
  return deCasteljau(column, m, u);
}

Bernstein2 derivativeU(const Bernstein2& p) {
  requireValid(p, "derivativeU");
  return mapColumns(p, std::max(p.degreeU - 1, 0), derivativeCoefficients);
}

Bernstein2 derivativeV(const Bernstein2& p) {
  requireValid(p, "derivativeV");
  return mapRows(p, std::max(p.degreeV - 1, 0), derivativeCoefficients);
}

Bernstein2 multiply(const Bernstein2& p, const Bernstein2& q) {
  requireValid(p, "multiply");
  requireValid(q, "multiply");
  const int m1 = p.degreeU;
  const int n1 = p.degreeV;
  const int m2 = q.degreeU;
  const int n2 = q.degreeV;
  requireDegree(static_cast<long long>(m1) + m2, "multiply");
  requireDegree(static_cast<long long>(n1) + n2, "multiply");
  const Coefficients wu = productWeights(m1, m2);
  const Coefficients wv = productWeights(n1, n2);
  const int n = n1 + n2;
  Bernstein2 r = zero2(m1 + m2, n);
  for (int i1 = 0; i1 <= m1; ++i1) {
    for (int j1 = 0; j1 <= n1; ++j1) {
      const double a = p.at(i1, j1);
      for (int i2 = 0; i2 <= m2; ++i2) {
        const double wa = wu[i1 * (m2 + 1) + i2] * a;
        double* out = r.coefficients.data() + (i1 + i2) * (n + 1) + j1;
        const double* w = wv.data() + j1 * (n2 + 1);
        for (int j2 = 0; j2 <= n2; ++j2) out[j2] += wa * w[j2] * q.at(i2, j2);
      }
    }
  }
  return r;
}

Bernstein2 add(const Bernstein2& p, const Bernstein2& q) { return combine(p, q, 1.0, "add"); }

Bernstein2 subtract(const Bernstein2& p, const Bernstein2& q) {
  return combine(p, q, -1.0, "subtract");
}

Bernstein2 scale(const Bernstein2& p, double s) {
  requireValid(p, "scale");
  Bernstein2 r = p;
  for (double& c : r.coefficients) c *= s;
  return r;
}

Bernstein2 elevate(const Bernstein2& p, int du, int dv) {
  requireValid(p, "elevate");
  if (du < 0 || dv < 0) {
    throw Error(fmt::format("elevate: elevations must be >= 0, got ({}, {})", du, dv));
  }
  requireDegree(static_cast<long long>(p.degreeU) + du, "elevate");
  requireDegree(static_cast<long long>(p.degreeV) + dv, "elevate");
  if (du == 0 && dv == 0) return p;
  const Bernstein2 alongU = mapColumns(
      p, p.degreeU + du, [du](const Coefficients& c) { return elevateCoefficients(c, du); });
  return mapRows(alongU, p.degreeV + dv,
                 [dv](const Coefficients& c) { return elevateCoefficients(c, dv); });
}

// Both halves of every column (stride `stride` between a column's coefficients, `count`
// columns `step` apart) in one de Casteljau pass each, with the arithmetic of
// splitCoefficients (so bitwise its results) and one scratch buffer for all of them: the
// quadtrees subdivide millions of times.
namespace {
void splitLines(const Bernstein2& p, int degree, std::size_t stride, int count, std::size_t step,
                double t, Bernstein2& left, Bernstein2& right) {
  const double s = 1.0 - t;
  const auto n = static_cast<std::size_t>(degree);
  std::vector<double> b(n + 1);
  for (int line = 0; line < count; ++line) {
    const std::size_t base = static_cast<std::size_t>(line) * step;
    for (std::size_t i = 0; i <= n; ++i) b[i] = p.coefficients[base + i * stride];
    left.coefficients[base] = b[0];
    right.coefficients[base + n * stride] = b[n];
    for (std::size_t r = 1; r <= n; ++r) {
      for (std::size_t i = 0; i <= n - r; ++i) b[i] = s * b[i] + t * b[i + 1];
      left.coefficients[base + r * stride] = b[0];
      right.coefficients[base + (n - r) * stride] = b[n - r];
    }
  }
}
}  // namespace

std::pair<Bernstein2, Bernstein2> subdivideU(const Bernstein2& p, double t) {
  requireValid(p, "subdivideU");
  std::pair<Bernstein2, Bernstein2> out{zero2(p.degreeU, p.degreeV), zero2(p.degreeU, p.degreeV)};
  // Columns: c_0j .. c_mj, degreeV + 1 apart; column j starts at j.
  splitLines(p, p.degreeU, static_cast<std::size_t>(p.degreeV + 1), p.degreeV + 1, 1, t,
             out.first, out.second);
  return out;
}

std::pair<Bernstein2, Bernstein2> subdivideV(const Bernstein2& p, double t) {
  requireValid(p, "subdivideV");
  std::pair<Bernstein2, Bernstein2> out{zero2(p.degreeU, p.degreeV), zero2(p.degreeU, p.degreeV)};
  // Rows: c_i0 .. c_in, contiguous; row i starts at i (degreeV + 1).
  splitLines(p, p.degreeV, 1, p.degreeU + 1, static_cast<std::size_t>(p.degreeV + 1), t,
             out.first, out.second);
  return out;
}

Bernstein2 restrictTo(const Bernstein2& p, double u0, double u1, double v0, double v1) {
  requireValid(p, "restrictTo");
  const Bernstein2 alongU = mapColumns(
      p, p.degreeU, [u0, u1](const Coefficients& c) { return restrictCoefficients(c, u0, u1); });
  return mapRows(alongU, p.degreeV,
                 [v0, v1](const Coefficients& c) { return restrictCoefficients(c, v0, v1); });
}

Bounds bounds(const Bernstein2& p) {
  requireValid(p, "bounds");
  const auto [lo, hi] = std::minmax_element(p.coefficients.begin(), p.coefficients.end());
  return {*lo, *hi};
}

bool mayVanish(const Bernstein2& p) {
  requireValid(p, "mayVanish");
  const auto positive = [](double c) { return c > 0.0; };
  const auto negative = [](double c) { return c < 0.0; };
  return !std::all_of(p.coefficients.begin(), p.coefficients.end(), positive) &&
         !std::all_of(p.coefficients.begin(), p.coefficients.end(), negative);
}

double EdgePowers::at(double u, double v) const {
  return std::pow(u, u0) * std::pow(1.0 - u, u1) * std::pow(v, v0) * std::pow(1.0 - v, v1);
}

std::vector<Bernstein2> divideEdgeFactors(std::vector<Bernstein2> polynomials, double threshold,
                                          EdgePowers& powers) {
  powers = {};
  if (polynomials.empty()) return polynomials;
  const int m0 = polynomials.front().degreeU, n0 = polynomials.front().degreeV;
  for (const Bernstein2& p : polynomials) {
    if (p.degreeU != m0 || p.degreeV != n0) {
      throw Error("divideEdgeFactors: the polynomials must share one bidegree");
    }
  }
  // The dropped coefficients' bound, grown with each division as the kept ones are scaled
  // (by at most the degree): rounding noise stays noise.
  double level = threshold;
  // Whether every polynomial's coefficients on one edge (row: the row i = index, an edge
  // u = 0 or 1; else the column j = index, v = 0 or 1) are within the threshold of zero.
  auto edgeVanishes = [&](bool row, int index) {
    for (const Bernstein2& p : polynomials) {
      const int count = row ? p.degreeV : p.degreeU;
      for (int k = 0; k <= count; ++k) {
        const double c = row ? p.at(index, k) : p.at(k, index);
        if (!(std::abs(c) <= level)) return false;
      }
    }
    return true;
  };
  // p / u (atStart) or p / (1 - u) along u (alongU), or the same along v.
  auto divide = [](const Bernstein2& p, bool alongU, bool atStart) {
    Bernstein2 q;
    q.degreeU = p.degreeU - (alongU ? 1 : 0);
    q.degreeV = p.degreeV - (alongU ? 0 : 1);
    q.coefficients.resize(static_cast<std::size_t>(q.degreeU + 1) * static_cast<std::size_t>(q.degreeV + 1));
    const int d = alongU ? p.degreeU : p.degreeV;
    for (int i = 0; i <= q.degreeU; ++i) {
      for (int j = 0; j <= q.degreeV; ++j) {
        const int k = alongU ? i : j;  // the index along the divided direction
        const double factor = atStart ? double(d) / (k + 1) : double(d) / (d - k);
        const double c = atStart ? (alongU ? p.at(i + 1, j) : p.at(i, j + 1)) : p.at(i, j);
        q.coefficients[static_cast<std::size_t>(i * (q.degreeV + 1) + j)] = c * factor;
      }
    }
    return q;
  };
  for (bool progress = true; progress;) {
    progress = false;
    for (int side = 0; side < 4; ++side) {
      const bool alongU = side < 2;
      const bool atStart = side % 2 == 0;
      const Bernstein2& p = polynomials.front();
      const int degree = alongU ? p.degreeU : p.degreeV;
      if (degree < 1) continue;
      if (!edgeVanishes(alongU, atStart ? 0 : degree)) continue;
      for (Bernstein2& q : polynomials) q = divide(q, alongU, atStart);
      level *= degree;
      int& power = side == 0 ? powers.u0 : side == 1 ? powers.u1 : side == 2 ? powers.v0 : powers.v1;
      ++power;
      progress = true;
    }
  }
  // Nothing left above the noise (a net whose r_u x r_v vanishes identically, collapsed to a
  // point or a line): exact zeros, not a direction made of rounding.
  bool noise = true;
  for (const Bernstein2& p : polynomials) {
    for (double c : p.coefficients) noise = noise && std::abs(c) <= level;
  }
  if (noise) {
    for (Bernstein2& p : polynomials) std::fill(p.coefficients.begin(), p.coefficients.end(), 0.0);
  }
  return polynomials;
}

Bernstein1 isoU(const Bernstein2& p, double u0) {
  requireValid(p, "isoU");
  Bernstein1 r{Coefficients(p.degreeV + 1)};
  for (int j = 0; j <= p.degreeV; ++j) r.coefficients[j] = evaluateCoefficients(columnOf(p, j), u0);
  return r;
}

Bernstein1 isoV(const Bernstein2& p, double v0) {
  requireValid(p, "isoV");
  Bernstein1 r{Coefficients(p.degreeU + 1)};
  for (int i = 0; i <= p.degreeU; ++i) r.coefficients[i] = evaluateCoefficients(rowOf(p, i), v0);
  return r;
}

}  // namespace scallop
