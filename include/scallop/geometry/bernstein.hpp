#pragma once
// Polynomials in Bernstein form on [0, 1] (univariate) and [0, 1]^2 (tensor product), the
// numerical kernel under the Bezier patches of the paper's eq. (1) and the Gauss-map
// computations built on them.
//
// Contract
// --------
// Representation. A univariate polynomial of degree n is p(t) = sum_i c_i b_i^n(t),
//         b_i^n(t) = C(n, i) (1 - t)^(n - i) t^i, stored as n + 1 coefficients c_0 .. c_n
//         (at least one; a function given an empty Bernstein1 throws scallop::Error). The
//         degree is the length of the basis, not the exact degree: leading power
//         coefficients may vanish. A tensor-product polynomial of bidegree (m, n) is
//         p(u, v) = sum_ij c_ij b_i^m(u) b_j^n(v), coefficient c_ij at index i (n + 1) + j;
//         degrees >= 0 and exactly (m + 1)(n + 1) coefficients, else scallop::Error. Degrees
//         of results are capped at kMaxBernsteinDegree per variable (binomial coefficients
//         stay finite in double up to C(1029, 514)); exceeding it throws scallop::Error.
// The zero polynomial (every coefficient 0.0) is an ordinary value: sums, products,
//         derivatives and subdivisions of it are zero polynomials of the usual degrees,
//         bounds(p) = {0, 0}, signVariations(p) = 0, mayVanish(p) = true. It has no isolated
//         roots: isolateRoots returns the single interval {0, 1, count 0, cluster true}
//         (count 0 with cluster true means "vanishes identically"; check isZero first), and
//         realRoots throws scallop::Error.
// Why Bernstein form. On [0, 1] the Bernstein basis is the best conditioned polynomial
//         basis (Farouki & Rajan, "On the numerical condition of polynomials in Bernstein
//         form", CAGD 4, 1987; "Algorithms for polynomials in Bernstein form", CAGD 5, 1988),
//         and the coefficients bound the polynomial (convex hull property) and count its roots
//         (variation diminishing: roots in (0, 1) <= sign variations, with equal parity).
//         Subdivision by the de Casteljau algorithm (Lane & Riesenfeld, "Bounds on a
//         polynomial", BIT 21, 1981) turns both into proofs on subintervals.
//
// Numerical behaviour (u = 2^-53 is the unit roundoff, gamma_k = k u / (1 - k u);
// Pbar(t) = sum_i |c_i| b_i^n(t) is the "absolute" polynomial, the scale of every error;
// binomial coefficients are exact in double up to degree 56, beyond it add (degree) u):
//   evaluate (de Casteljau, O(n^2)): |computed - p(t)| <= gamma_{3n} Pbar(t) for t in [0, 1]
//         (every step is a convex combination; each of 1 - t, two products and a sum rounds).
//   subdivide / restrictTo / elevate / multiply: each output coefficient is a convex (for
//         multiply: positively weighted) combination of the inputs, off by at most
//         gamma_{3n} (subdivide), gamma_{6n} (restrictTo, a, b in [0, 1]; the computed
//         interval's ends are off by <= 3u (2|a| + |b|)), gamma_{min(n,r)+4} (elevate by r),
//         gamma_{min(m,n)+5} (multiply) times the same combination of the |inputs|, so the
//         error of the result at t is that factor times Pbar(t) (Pbar(t) Qbar(t) for a
//         product). Tensor product: the univariate bounds along u and along v add up;
//         multiply: gamma_{(min(m1,m2)+1)(min(n1,n2)+1)+9}. evaluate: gamma_{3(m+n)}.
//   fromPowerBasis: coefficient i off by gamma_{i+2} sum_j C(i,j)/C(n,j) |a_j|. toPowerBasis is
//         ill-conditioned by nature (amplification up to 3^n) and meant for tests.
//   derivative: exact differences of the inputs up to one rounding each (2u relative).
// Roots. isolateRoots proves what it reports, for every polynomial whose coefficients lie
//         within one rounding (relative u) of the given ones (so within a rounding of an ideal
//         polynomial the caller approximated), by running error bounds (Higham, "Accuracy and
//         Stability of Numerical Algorithms", 3.3) carried through each subdivision:
//         - an interval with cluster == false holds exactly one root, and it is simple;
//         - an interval with cluster == true holds at most `count` roots counted with
//           multiplicity (count >= 1), and the number of roots has the parity of count;
//           these are roots we could not separate at this precision (a multiple root, roots
//           closer than the rounding noise allows, or a double root that may be a complex
//           pair in the perturbed family). For a multiple root or a tight cluster count is its
//           multiplicity; on a badly conditioned stretch (a root condition number times u
//           above the root spacing, e.g. 40 or more equally spaced roots in [0, 1]) the bound
//           can exceed the number of roots of the ideal polynomial;
//         - no root of the family lies outside the reported intervals ("never silently
//           lost"). Exact roots at t = 0 or t = 1 (leading or trailing zero coefficients,
//           multiplicity = their number) come first / last as the intervals [0, 0] / [1, 1].
//         After D halvings a coefficient's error bound is at most (1 + 2nD) u max|c|, so a root
//         of multiplicity mu at r, with D_mu = |p^(mu)(r)| / mu!, is reported in a cluster of
//         width about 2 (3 (1 + 2nD) u max|c| / D_mu)^(1/mu) (D <= 40 at the default
//         resolution): ~1e-6 for a double root of a well-scaled polynomial of degree 10.
//         realRoots refines each simple interval to full precision (|error| about
//         gamma_{3n} Pbar(r) / |p'(r)|, the root's condition number times the evaluation
//         error) and reports a cluster as its midpoint repeated `count` times.
// Complexity. evaluate O(n^2), derivative O(n), multiply O(mn), elevate by r O(n r + r^2),
//         subdivide and restrictTo O(n^2); isolateRoots O(n^2) per subdivision, O(n^2 log(1/d))
//         per isolated root with d the root separation (bisection), plus O(n^3) per cluster;
//         tensor-product operations are the univariate ones along rows and columns.

#include <utility>
#include <vector>

namespace scallop {

/// Largest degree (per variable) a result may have; see the file comment.
constexpr int kMaxBernsteinDegree = 1000;

/// p(t) = sum_i coefficients[i] C(n, i) (1 - t)^(n - i) t^i on [0, 1], n = degree().
struct Bernstein1 {
  std::vector<double> coefficients;  ///< c_0 .. c_n, at least one
  /// n = number of coefficients - 1 (-1 for an empty, invalid, polynomial).
  int degree() const { return static_cast<int>(coefficients.size()) - 1; }
};

/// p(t) by the de Casteljau algorithm (any finite t; stable for t in [0, 1], see the bound above).
double evaluate(const Bernstein1& p, double t);
/// p'(t) in Bernstein form, degree n - 1: n (c_{i+1} - c_i). A constant gives the zero constant.
Bernstein1 derivative(const Bernstein1& p);
/// p q, degree m + n: (pq)_k = sum_{i+j=k} C(m,i) C(n,j) / C(m+n,k) a_i b_j.
Bernstein1 multiply(const Bernstein1& p, const Bernstein1& q);
/// p + q, degree max(m, n); the lower degree operand is elevated first.
Bernstein1 add(const Bernstein1& p, const Bernstein1& q);
/// p - q, degree max(m, n); the lower degree operand is elevated first.
Bernstein1 subtract(const Bernstein1& p, const Bernstein1& q);
/// s p (same degree).
Bernstein1 scale(const Bernstein1& p, double s);
/// The same polynomial written in degree n + times (times >= 0, else scallop::Error).
Bernstein1 elevate(const Bernstein1& p, int times);
/// De Casteljau subdivision at t: {left, right} with left(s) = p(t s), right(s) = p(t + (1 - t) s).
std::pair<Bernstein1, Bernstein1> subdivide(const Bernstein1& p, double t);
/// q(s) = p(a + (b - a) s): p on [a, b] mapped to [0, 1]. Any finite a, b (a > b reverses,
/// a == b gives the constant p(a)); the two de Casteljau passes divide by max(|b|, |1 - a|),
/// which is >= 1/2 for a, b in [0, 1].
Bernstein1 restrictTo(const Bernstein1& p, double a, double b);

/// From the power basis: p(t) = sum_j a_j t^j, degree = a.size() - 1 (a non-empty).
Bernstein1 fromPowerBasis(const std::vector<double>& powerCoefficients);
/// To the power basis (ill-conditioned for high degree; intended for tests and debugging).
std::vector<double> toPowerBasis(const Bernstein1& p);

/// min and max of the coefficients: lo <= p(t) <= hi on [0, 1] (convex hull property).
struct Bounds {
  double lo = 0.0;
  double hi = 0.0;
};
Bounds bounds(const Bernstein1& p);
/// Number of sign changes in c_0 .. c_n, zeros skipped: an upper bound on the number of roots
/// in (0, 1) counted with multiplicity, of the same parity (Descartes' rule in Bernstein form).
int signVariations(const Bernstein1& p);
/// True if every coefficient is 0.0 (the polynomial vanishes identically).
bool isZero(const Bernstein1& p);

/// An interval of [0, 1] holding roots; see the file comment for what is proved.
struct RootInterval {
  double lo = 0.0;
  double hi = 0.0;
  int count = 0;         ///< roots counted with multiplicity (exact if !cluster; see above)
  bool cluster = false;  ///< true: could not be separated to the resolution
};

struct RootOptions {
  double resolution = 1e-12;  ///< stop subdividing intervals narrower than this (>= 0)
  int maxDepth = 60;          ///< and beyond this many halvings of [0, 1] (>= 0)
};

/// Real roots on [0, 1], isolated by halving [0, 1] (de Casteljau at 1/2, exact
/// interval ends) while sign variations of the certified coefficient signs exceed one. An
/// interval is dropped when its coefficients are provably of one sign, kept as simple when
/// they provably show one variation, and declared unresolved when narrower than the
/// resolution, deeper than maxDepth, or when every coefficient is within its error bound
/// (inside the rounding noise, where halving cannot separate anything). Adjacent unresolved
/// intervals are merged; the count of a merged interval J is the smallest k for which the
/// k-th derivative is provably of one sign on J (Rolle: at most k roots), capped by the
/// largest possible sign variation count on J, and lowered by one if needed to the parity of
/// the (certified) signs at J's ends. Sorted, interiors disjoint. Throws scallop::Error for
/// non-finite coefficients or invalid options.
std::vector<RootInterval> isolateRoots(const Bernstein1& p, const RootOptions& options = {});

/// Roots on [0, 1] in increasing order, each repeated with its multiplicity: simple roots
/// refined by a safeguarded Newton iteration (bisection whenever Newton leaves the bracket or
/// converges slowly) to a bracket of a few ulps; a cluster reported as its midpoint repeated
/// `count` times; exact roots at 0 and 1 as 0.0 and 1.0. Throws scallop::Error for the zero
/// polynomial (every t is a root) and as isolateRoots.
std::vector<double> realRoots(const Bernstein1& p, const RootOptions& options = {});

/// p(u, v) = sum_ij c_ij b_i^m(u) b_j^n(v) on [0, 1]^2, (m, n) = (degreeU, degreeV).
struct Bernstein2 {
  int degreeU = 0;
  int degreeV = 0;
  std::vector<double> coefficients;  ///< c_ij at index i (degreeV + 1) + j
  /// c_ij, unchecked (as std::vector::operator[]).
  double at(int i, int j) const { return coefficients[i * (degreeV + 1) + j]; }
};

/// p(u, v): de Casteljau in v along each row, then in u. O(mn(m + n)); error <=
/// gamma_{3(m+n)} Pbar(u, v).
double evaluate(const Bernstein2& p, double u, double v);
/// dp/du, bidegree (m - 1, n); (0, n) zero polynomial when m == 0.
Bernstein2 derivativeU(const Bernstein2& p);
/// dp/dv, bidegree (m, n - 1); (m, 0) zero polynomial when n == 0.
Bernstein2 derivativeV(const Bernstein2& p);
/// p q, bidegree (m1 + m2, n1 + n2).
Bernstein2 multiply(const Bernstein2& p, const Bernstein2& q);
/// p + q, bidegree (max, max) after elevation.
Bernstein2 add(const Bernstein2& p, const Bernstein2& q);
/// p - q, bidegree (max, max) after elevation.
Bernstein2 subtract(const Bernstein2& p, const Bernstein2& q);
/// s p.
Bernstein2 scale(const Bernstein2& p, double s);
/// The same polynomial in bidegree (m + du, n + dv), du, dv >= 0.
Bernstein2 elevate(const Bernstein2& p, int du, int dv);
/// Split at u = t: {p on [0, t] x [0, 1], p on [t, 1] x [0, 1]}, each mapped to [0, 1]^2.
std::pair<Bernstein2, Bernstein2> subdivideU(const Bernstein2& p, double t);
/// Split at v = t: {p on [0, 1] x [0, t], p on [0, 1] x [t, 1]}, each mapped to [0, 1]^2.
std::pair<Bernstein2, Bernstein2> subdivideV(const Bernstein2& p, double t);
/// q(s, r) = p(u0 + (u1 - u0) s, v0 + (v1 - v0) r) (restrictTo along u, then along v).
Bernstein2 restrictTo(const Bernstein2& p, double u0, double u1, double v0, double v1);
/// min and max coefficient: bounds of p on [0, 1]^2.
Bounds bounds(const Bernstein2& p);
/// False when every coefficient is > 0 or every coefficient is < 0, which proves p has no
/// zero on [0, 1]^2; true otherwise (p may vanish). The test of a quadtree on the zero set.
bool mayVanish(const Bernstein2& p);
/// Exponents of the edge factors u^u0 (1 - u)^u1 v^v0 (1 - v)^v1 split off polynomials by
/// divideEdgeFactors.
struct EdgePowers {
  int u0 = 0;  ///< the power of u (the edge u = 0)
  int u1 = 0;  ///< the power of 1 - u (the edge u = 1)
  int v0 = 0;  ///< the power of v (the edge v = 0)
  int v1 = 0;  ///< the power of 1 - v (the edge v = 1)
  bool any() const { return u0 + u1 + v0 + v1 > 0; }
  /// u^u0 (1 - u)^u1 v^v0 (1 - v)^v1 at (u, v).
  double at(double u, double v) const;
};

/// Divides polynomials of one bidegree by the edge factors they share: while every one of
/// them has its coefficients on the edge u = 0 (the row c_0j) at most `threshold` in
/// magnitude, they all vanish on that edge to within it, and p = u q with
/// q_ij = c_(i+1)j m / (i + 1) (b_(i+1)^m(u) = (m / (i + 1)) u b_i^(m-1)(u)); likewise
/// 1 - u (c_ij m / (m - i), the row c_mj dropped), v and 1 - v. The bound grows by the
/// degree with each division (the kept coefficients are scaled by up to it, and so is their
/// noise). Exact but for the dropped coefficients and one rounding per coefficient and
/// division; a degree never drops below 0, and quotients whose every coefficient is within
/// the grown bound (rounding noise of a polynomial that vanishes identically) are returned
/// as exact zeros. Returns the quotients; `powers` receives the exponents split off.
/// O(k mn) for k divisions.
std::vector<Bernstein2> divideEdgeFactors(std::vector<Bernstein2> polynomials, double threshold,
                                          EdgePowers& powers);

/// The iso-parameter line u = u0: v -> p(u0, v), degree n (for patch boundaries: u0 = 0, 1).
Bernstein1 isoU(const Bernstein2& p, double u0);
/// The iso-parameter line v = v0: u -> p(u, v0), degree m (for patch boundaries: v0 = 0, 1).
Bernstein1 isoV(const Bernstein2& p, double v0);

}  // namespace scallop
