#pragma once
// Tensor-product Bezier patches (the paper's eq. (1), any bidegree, bicubic first-class):
// points, partial derivatives, normals (eq. (2)), subdivision, and the exact Bernstein-form
// polynomials that the Gauss-map computations need (normal components along the boundary,
// the Gaussian-curvature numerator whose zero set is the parabolic lines, the squared normal
// length for the regularity check). Smith, Farouki, al-Kandari and Pottmann, "Optimal slicing
// of free-form surfaces" (sections 2 and 3.1), after Smith and Farouki, "Gauss map computation
// for free-form surfaces", CAGD 18, 2001.
//
// Contract
// --------
// Patch:  r(u, v) = sum_j sum_k p_jk b_j^m(u) b_k^n(v), (u, v) in [0, 1]^2, with
//         (m, n) = (degreeU, degreeV), both >= 1, and (m + 1)(n + 1) control points stored
//         row by row: control[j (n + 1) + k] = p_jk (j along u, k along v). Units are the
//         caller's (the paper's test surfaces are in inches). Every function validates the
//         patch and throws scallop::Error when it is malformed (degrees < 1 or wrong count).
// Parameters u, v may be any finite values; [0, 1] is the patch and where the error bounds hold.
// Evaluation: differences of the control net first (the hodograph), then de Casteljau in v
//         along each row and in u across the rows: O(mn(m + n)) per call, backward stable:
//         per coordinate, |error| <= gamma_{3(m+n)+4} F sum_jk A_jk b_j(u) b_k(v) (u = 2^-53,
//         gamma_k = k u / (1 - k u)), F the degree factor m!/(m-a)! n!/(n-b)! of the order
//         (a, b) and A_jk the |control point| (order 0), the |first difference| (order 1), or
//         the sum of the two |first differences| a second difference combines (order 2):
//         errors scale with the differences, not with the coordinates.
// unitNormal (eq. (2)): n = (r_u x r_v) / |r_u x r_v|. Throws scallop::Error naming (u, v)
//         when the cross product is zero to within its rounding error, i.e. when
//         |r_u x r_v| <= (6(m + n) + 8) u S_u S_v, S_u = m max|p_{j+1,k} - p_jk|,
//         S_v = n max|p_{j,k+1} - p_jk| (bounds on |r_u| and |r_v| over the patch): there
//         the direction of the computed normal may be rounding noise. Scale-invariant (a
//         relative test): sin(angle(r_u, r_v)) |r_u||r_v| / (S_u S_v) below ~5e-15 (bicubic).
// Polynomial views (exact Bernstein forms, coefficients rounded as bernstein.hpp describes):
//         coordinatePolynomials   x, y, z: bidegree (m, n), coefficients = control coordinates;
//         normalPolynomials       N = r_u x r_v: bidegree (2m - 1, 2n - 1) (bicubic: (5, 5));
//         gaussianCurvatureNumerator  (r_uu . N)(r_vv . N) - (r_uv . N)^2, bidegree
//                                 (6m - 4, 6n - 4) (bicubic: (14, 14)). Since
//                                 L = r_uu . N / |N| etc. and EG - F^2 = |N|^2, it equals
//                                 K |N|^4: the sign of the Gaussian curvature K wherever the
//                                 patch is regular; its zero set is the parabolic lines;
//         normalLengthSquared     |N|^2, bidegree (4m - 2, 4n - 2): the patch is regular iff
//                                 it has no zero on [0, 1]^2 (mayVanish false proves it).
//         Cost: O(m^2 n^2) flops for each (products of Bernstein forms); bicubic: the
//         curvature numerator takes about 10^5 flops.
// Certifying that no normal lies within an angle alpha of a direction d (|d| = 1, normals
//         symmetrized: n and -n): |n . d| <= cos(alpha) everywhere iff
//         A = cos^2(alpha) |N|^2 - (N . d)^2 >= 0 on [0, 1]^2, with
//         N . d = d.x N_x + d.y N_y + d.z N_z from normalPolynomials (use scale and add) and
//         |N|^2 = normalLengthSquared. Coefficients of A all > 0 prove it on a (sub-)patch
//         (restrictTo / subdivideU / subdivideV to refine, as the quadtree on the parabolic
//         lines); mind the rounding of the coefficients (bernstein.hpp) near A = 0.
// Subdivision: de Casteljau along one parameter (Lane & Riesenfeld 1981), O(mn(m + n)).
// Rational patches (issue 14, item 2): with weights w_jk > 0 (BezierPatch::weights),
//         r = X / w, X(u, v) = sum w_jk p_jk b_j b_k, w(u, v) = sum w_jk b_j b_k: every
//         exact cylinder, cone, sphere and torus. Points and derivatives to second order by
//         the quotient rule on the homogeneous (X, w) (r_u = (X_u - w_u r) / w, r_uu =
//         (X_uu - 2 w_u r_u - w_uu r) / w, r_uv = (X_uv - w_u r_v - w_v r_u - w_uv r) / w);
//         subdivision on the homogeneous net (the weights stay positive). The polynomial
//         views stay polynomial once the weights are cleared:
//           normalPolynomials  N = w X_u x X_v - w_v X_u x X - w_u X x X_v = w^3 r_u x r_v
//                              (the same direction), bidegree (3m - 1, 3n - 1);
//           gaussianCurvatureNumerator  A B - C^2 with A = w X_uu . N - w_uu X . N,
//                              B = w X_vv . N - w_vv X . N, C = w X_uv . N - w_uv X . N
//                              (w^2 r_uu . N = A since r_u . N = 0, and so on): w^4 times
//                              the polynomial case's, the same sign, bidegree (10m - 4,
//                              10n - 4);
//           normalLengthSquared  |N|^2 of that N.
//         The unit normal's rounding threshold takes S_u = (m max|X_{j+1,k} - X_jk| + m
//         max|w_{j+1,k} - w_jk| max|p_jk|) / min w (a bound on |r_u| by the quotient rule),
//         likewise S_v, and the factor (6(m + n) + 16) u. coordinatePolynomials is for
//         polynomial patches (scallop::Error on a rational one): the modules that take
//         rational patches work on homogeneousPolynomials' X and w instead (sections, the
//         design heights), or on homogeneous nets (distances).

#include <array>
#include <utility>
#include <vector>

#include "scallop/geometry/bernstein.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

struct BezierPatch {
  int degreeU = 3;  ///< m >= 1
  int degreeV = 3;  ///< n >= 1
  /// (m + 1)(n + 1) control points, control[j (n + 1) + k] = p_jk multiplying b_j^m(u) b_k^n(v).
  std::vector<Vec3> control;
  /// p_jk, unchecked (as std::vector::operator[]).
  const Vec3& at(int j, int k) const { return control[j * (degreeV + 1) + k]; }
  /// A rational patch's weights w_jk > 0, stored as `control`; empty: polynomial (all 1).
  std::vector<double> weights{};
  bool rational() const { return !weights.empty(); }
  /// w_jk (1 for a polynomial patch), unchecked.
  double weight(int j, int k) const { return weights.empty() ? 1.0 : weights[j * (degreeV + 1) + k]; }
};

/// r(u, v), eq. (1).
Vec3 point(const BezierPatch& patch, double u, double v);
/// r_u(u, v).
Vec3 derivativeU(const BezierPatch& patch, double u, double v);
/// r_v(u, v).
Vec3 derivativeV(const BezierPatch& patch, double u, double v);
/// r_uu (du = 2, dv = 0), r_uv (1, 1) or r_vv (0, 2); other orders throw scallop::Error.
Vec3 secondDerivative(const BezierPatch& patch, double u, double v, int du, int dv);
/// r_u x r_v, not normalised (zero where the patch is not regular).
Vec3 normalVector(const BezierPatch& patch, double u, double v);
/// The unit normal of eq. (2); on a collapsed edge (an apex row), its limit from inside the
/// patch (normalDirectionPolynomials); within 1e-6 of a corner where q vanishes to first
/// order (surface.hpp's cornerPieces), the limit along the ray from the corner through
/// (u, v) (at the corner itself, along the diagonal); throws scallop::Error naming (u, v)
/// where r_u x r_v vanishes otherwise.
Vec3 unitNormal(const BezierPatch& patch, double u, double v);

/// r_u, r_v, r_uu, r_uv and r_vv at one point, from the Bernstein basis and its derivatives
/// in one pass over the control net (the separate functions above each difference the net).
struct PatchDerivatives {
  Vec3 u, v, uu, uv, vv;
};
PatchDerivatives derivativesToSecondOrder(const BezierPatch& patch, double u, double v);
/// The same and r(u, v) itself, in `value`, from the same pass: the basis sums
/// sum_j b_j^m(u) sum_k b_k^n(v) p_jk, O(m^2 + n^2 + mn) where point()'s de Casteljau is
/// O(mn(m + n)). For a polynomial patch, per coordinate |error| <= gamma_{4(m+n)+2}
/// sum_jk |p_jk| b_j(u) b_k(v) (the bases by their triangle, 3 roundings a level; the sums,
/// one rounding a term and a level), and it may differ from point() in the last bits; a
/// rational patch's is X / w from the same sums, exactly what its point() returns.
PatchDerivatives derivativesToSecondOrder(const BezierPatch& patch, double u, double v, Vec3& value);
/// (r_uu . N)(r_vv . N) - (r_uv . N)^2 with N = r_u x r_v at (u, v): the value of
/// gaussianCurvatureNumerator there, from derivativesToSecondOrder (cheaper than the
/// polynomial of bidegree (6m - 4, 6n - 4)).
double gaussianCurvatureNumeratorAt(const BezierPatch& patch, double u, double v);

/// Split at u = t: {patch on [0, t] x [0, 1], patch on [t, 1] x [0, 1]}, each reparametrised
/// to [0, 1]^2.
std::pair<BezierPatch, BezierPatch> subdivideU(const BezierPatch& patch, double t);
/// Split at v = t: {patch on [0, 1] x [0, t], patch on [0, 1] x [t, 1]}.
std::pair<BezierPatch, BezierPatch> subdivideV(const BezierPatch& patch, double t);
/// The sub-patch (s, r) -> r(u0 + (u1 - u0) s, v0 + (v1 - v0) r).
BezierPatch restrictTo(const BezierPatch& patch, double u0, double u1, double v0, double v1);

/// x(u, v), y(u, v), z(u, v) in Bernstein form, bidegree (m, n); scallop::Error for a rational
/// patch (its coordinates are quotients).
std::array<Bernstein2, 3> coordinatePolynomials(const BezierPatch& patch);
/// The components of N = r_u x r_v, bidegree (2m - 1, 2n - 1); of a rational patch,
/// w^3 r_u x r_v (see the contract), bidegree (3m - 1, 3n - 1).
std::array<Bernstein2, 3> normalPolynomials(const BezierPatch& patch);
/// (r_uu . N)(r_vv . N) - (r_uv . N)^2 = K |N|^4, bidegree (6m - 4, 6n - 4); of a rational
/// patch a positive multiple of it (see the contract), bidegree (10m - 4, 10n - 4).
Bernstein2 gaussianCurvatureNumerator(const BezierPatch& patch);
/// |r_u x r_v|^2, bidegree (4m - 2, 4n - 2) (rational: |N|^2 of normalPolynomials' N).
Bernstein2 normalLengthSquared(const BezierPatch& patch);
/// A rational (or polynomial) patch's homogeneous coordinates X = w r (x, y, z) and w in
/// Bernstein form, bidegree (m, n): coefficients w_jk p_jk and w_jk.
std::array<Bernstein2, 4> homogeneousPolynomials(const BezierPatch& patch);

/// The normal's direction field with collapsed edges factored out: N = r_u x r_v =
/// u^a (1 - u)^b v^c (1 - v)^d q, where a boundary row or column of the control net collapses
/// to a point (an apex: r_v = 0 along u = 0, say) N vanishes on that edge and the limit of
/// the unit normal there is q / |q|. q is N divided by the edge factors under which all three
/// components vanish to within unitNormal's rounding threshold (bernstein.hpp's
/// divideEdgeFactors); q = N (powers zero) for a patch with no such edge. q is parallel to N,
/// with the same sense, wherever N != 0, so every use of N's direction (the Gauss map, the
/// certificate, the membership test) takes q alike. Where q itself vanishes on the closed
/// patch (a corner where the limit depends on the direction of approach, or an interior
/// singularity) the patch is not regular (surface.hpp).
struct NormalDirection {
  std::array<Bernstein2, 3> polynomials;
  EdgePowers powers;
};
NormalDirection normalDirectionPolynomials(const BezierPatch& patch);

/// The sign of the Gaussian curvature as a polynomial: gaussianCurvatureNumerator = K |N|^4
/// divided by the edge factors on which it vanishes (every coefficient of the edge's row
/// below 1e-12 of the bound on its terms, |r_uu . N| |r_vv . N| + |r_uv . N|^2): collapsed
/// edges (N = u^a q there, so K |N|^4 has u^(2a) at least), and parabolic lines that run
/// along a patch edge (the rim of a surface of revolution whose profile has an inflection at
/// its end). Inside the patch its sign is K's; on such an edge it is the sign of K's limit
/// from inside, so the edge is no parabolic line for the Gauss map's quadtree.
struct CurvatureSign {
  Bernstein2 polynomial;
  EdgePowers powers;
};
CurvatureSign curvatureSignPolynomial(const BezierPatch& patch);

/// unitNormal's threshold: |r_u x r_v| at most (6(m + n) + 8) u S_u S_v is rounding noise.
double normalRoundingThreshold(const BezierPatch& patch);

}  // namespace scallop
