#pragma once
// A proof that no slicing direction exists: that the symmetrized Gauss map of a surface
// covers the whole sphere, i.e. that for every unit m, m or -m is a surface normal, so the
// optimal slicing angle alpha* of Smith, Farouki, al-Kandari and Pottmann ("Optimal slicing
// of free-form surfaces", CAGD 2002) is exactly 0. Nothing here ever claims the opposite:
// a failed proof only says where no proof was found.
//
// Contract
// --------
// Input:  a surface of Bezier patches (surface.hpp); regular patches are the design case.
//         Patches with collapsed boundary rows (apexes) are accepted: the normal there is
//         the limit q / |q| (bezier.hpp's normalDirectionPolynomials, q = N with the
//         collapsed edges' factors divided out); rectangles where |q| is not bounded below
//         are skipped. Malformed patches (degree < 1, wrong control count) throw
//         scallop::Error, as do invalid options.
// Output: NormalCoverage. proven == true is a proof (rigorous up to the floating-point
//         rounding bounds stated below) that every direction m has m or -m among the unit
//         normals n = q / |q| (= N / |N|, N = r_u x r_v, wherever N != 0; on an apex row its
//         limit) of the patches on [0, 1]^2. proven == false names a direction whose cap
//         could not be proven (not a claim that it is uncovered).
// Method (degree theory): the directions up to sign are the three cube faces x, y, z = 1
//         projected to the sphere (every m has m or -m on one); each face is a square of
//         the gnomonic chart, subdivided into quadrants depth first. A quadrant's spherical
//         image lies in the cap C of centre c (its centre's direction) and angular radius r
//         (the farthest corner: caps below 90 degrees are convex). C is proven when a
//         rectangle D of one patch satisfies, in the gnomonic chart about c,
//         g(x) = (x . e1, x . e2) / (x . c), with s = +1 or -1 (C covered by n or by -n):
//         1. |N| is bounded below on D: with d the normal at D's centre, every Bernstein
//            coefficient of d . N on D exceeds the coefficients' rounding bound (so
//            |N| >= d . N > 0), and the normals lie within rho = atan(max |N - (d . N) d| /
//            min d . N) of d (both bounded by the coefficients: convex hull),
//            rho <= maxCellSpreadRad, angle(s d, c) + rho < 90 degrees less 0.1 rad, so
//            s n . c >= cmin > 0 on D and g(s n) is defined on D;
//         2. along each edge of D (parameter t in [0, 1]) |dn/dt| <= |dN/dt| / |N|, bounded
//            by K_n = (largest |Bernstein coefficient| of dN/dt on the edge) / (least
//            coefficient of d . N on it); the chart stretches tangent vectors by at most
//            1 / cmin^2, so the curve gamma = g(s n(t)) is K = K_n / cmin^2 -Lipschitz;
//         3. the edge is sampled (adaptive bisection) so that every segment [a, b] between
//            samples t_a < t_b satisfies |a| + |b| - 2 tan(r) > K (t_b - t_a) + 2 eps: the
//            piece of gamma over [t_a, t_b] lies in the ellipse |x - a| + |x - b| <=
//            K (t_b - t_a), which contains the segment, is convex and misses the disk of
//            radius tan(r) about g(c) = 0 (the image of C); so the straight homotopy from
//            gamma to the polygon avoids that disk, and gamma winds about every point of it
//            as the polygon does about 0;
//         4. that winding number is nonzero. Then every direction of C is a value of the
//            continuous map s n on the disk D (a map of a disk whose boundary winds about a
//            point takes that point), i.e. a normal of the patch up to sign.
// Glued assemblies (directions whose preimages lie on seams, seam crossings, apexes, or
//         free edges): D may be a chain c = sum_i o_i D_i of rectangles D_i of patches P_i,
//         orientations o_i = +-1, steps 1 - 3 holding on each (each with its own sign s_i),
//         where some sides are glued in pairs and some are apex rows:
//         - two patch edges are glued when q along them, the second's parameter t or 1 - t,
//           is parallel as a polynomial: every Bernstein coefficient of q_A x q_B (degree 2d)
//           lies within its rounding bound of 0 (gamma_{2d+12} of the coefficients' absolute
//           sums, plus the q coefficients' own bounds through the products). Then the unit
//           normals s_A n_A and s_B n_B, both in the chart's open hemisphere and parallel,
//           are equal along the glued sides. The surface's seams (control points equal bit
//           for bit, G1 within rounding: the teapot's meridians and parallels) are glued so,
//           and so are free edges whose normals are antipodal (the teapot bottom's rim with
//           the opposite quarter's), the two sides being s = +1 and s = -1;
//         - a side on a collapsed edge (its control points all equal) whose q coefficients
//           are all parallel (within their rounding) is an apex row: s n is constant on it;
//         - so is a side of a fold strip (below) whose own restricted q coefficients are all
//           parallel to the first and on its side (|a_j x a_0| within the bound of their
//           rounding, a_j . a_0 > 0): q = lambda a_0 with lambda > 0 along it, its unit
//           normal constant (the teapot rim's top parallel, u = 1/2 of each quarter);
//         - glued sides have equal parameter intervals (bounds are multiples of 2^-20, so
//           1 - t is exact) and the orientations are chosen so that they cancel in the
//           boundary of c.
//         Then the map F = s_i n_i on the space X (the D_i, glued sides identified) is
//         continuous into the hemisphere, and the boundary of c, less the constant sides
//         (apex rows and fold sides: F o sigma is a constant 1-simplex, the boundary of the
//         constant 2-simplex at that value), is a cycle made of the remaining sides. If F
//         missed a point y of the cap's disk, F_* c would be a 2-chain in R^2 \ {y}, its
//         boundary F_* (boundary of c) = (the remaining sides' images) + (boundaries of
//         constant 2-simplices, also in R^2 \ {y}, since their value is F's), so the
//         remaining cycle would bound there and its winding about y would be 0. This holds
//         for every y, the constant sides' value e included (F takes e, so it misses no
//         point equal to e): only the sampled sides must avoid the cap's disk, which is why a
//         fold's strips must close into a ring (a lone strip's sides meet the fold side, at
//         e, inside the cap). So the sides are
//         sampled as in step 3 and their turning angles about 0, times o_i, summed: the sum
//         is 2 pi k up to the turn between the computed and the true ends of sides that meet
//         another rectangle's side or an apex (bounded by asin(eps / |x|) each, in all < 1
//         rad); k != 0 proves the cap. The assembly grows from the rectangle about a
//         preimage: across its sides on glued edges, to the partner's rectangle with the same
//         interval and depth, one side at a time, closing into a cycle around a vertex (the 4
//         quarters at a seam crossing, the bottom's rim corners) or around an apex (strips
//         the whole apex row long, the knob's top and the bottom's centre), or else a chain
//         (one seam), at most 8 rectangles. The surface's shared edges are tried first.
//         Fold strips (tried last for each preimage, when the rectangles about it fail): when
//         the preimage's u (or v) rounds, at a dyadic level 1 .. 10 and within 8 tan(r) /
//         (the Jacobian's largest singular value) of it, to a t in (0, 1) whose line u = t
//         has q at its two ends parallel (a screen) and q's coefficients along it parallel
//         (restricted to the line, cached: the screen; each strip certifies its own side), the
//         strips t <= u <= t + d and t - d <= u <= t, 0 <= v <= 1 (the preimage's side
//         first; d = |u - t| plus the apex strips' depth, up to a multiple of 2^-20, at most
//         1/2) are grown across glued edges into a ring (the rim's four quarters) and tested
//         with their constant sides dropped.
//         Rectangles are chosen, not searched blindly: Newton's method on g(s n(u, v)) = 0
//         from the parent cap's preimages (first) and from a fixed 4 x 4 grid of seed cells
//         per patch whose normal cone holds c (when those fail) finds the preimages of c, and
//         rectangles centred there (moved inside the patch; sizes dyadic) are tried at sizes
//         from the chart Jacobian's smallest singular value (strips along an apex row: depth
//         from the largest), first as the assembly they grow into, then alone; any heuristic
//         failure costs completeness, never soundness. A cap not proven is
//         split in four, to maxCapDepth; a cap at that depth, or a centre with no preimage
//         found, ends the proof with that direction reported.
// Rounding: the restricted Bernstein coefficients carry bernstein.hpp's bounds
//         (gamma_{6m} + gamma_{6n} of the largest |coefficient| of N or q, times 4; on patches
//         with apex rows plus the edge division's: its dropped row, below unitNormal's
//         threshold, and one rounding per division, amplified by the degree per division),
//         which are subtracted from the lower bounds and added to the derivative bounds; the
//         sampled chart points carry eps (their evaluation error through 1 / |q| and the
//         chart, times 4); the cap's radius is rounded up. The glue certificate and the apex
//         rows' constancy are identities up to those coefficient bounds: a seam whose normals
//         differ by a kink below rounding (the teapot's parallels, G1 in decimal, differ by
//         ~1e-16 in binary) is glued. Those are the "stated rounding".
// Limits: a direction whose every preimage lies on a fold (a parabolic line, where the Gauss
//         map is not locally onto) other than an iso-parameter line of constant normal at a
//         dyadic parameter (the teapot rim's top parallel is one and is proven; the same rim
//         with its profile's top moved off u = 1/2 is not), on a free edge with no antipodal
//         partner, at a corner whose walk does not close, or only at points where q = 0 is not
//         proven. Not proven, and not provable by any assembly: "teapot-spout". Its
//         +-(0, 1, 0) is a normal only at the ends of the side lines v = 1/2: on the free
//         edges (where the spout joins the body, and the lip) and on the seams between the
//         lower and upper spout, where the Gauss map folds (local degree 0: a small circle's
//         image winds 0 times about it). An assembly whose boundary avoids a cap holding
//         (0, 1, 0) keeps the free-edge points off it, so its winding about (0, 1, 0) is the
//         sum of those local degrees, 0; the caps are closed and (0, 1, 0) is a corner of
//         four. The directions about it are normals (tests: gauss_map's membership test,
//         even in the lens between a free edge's image and its mirror's, which the seam's
//         fold covers).
// Complexity: the glue table costs O(P^2) edge pairs (a 5-point screen, then O(d^2) for the
//         certificate); per cap O(P) for the seed cones (P patches) plus a few Newton solves
//         and assembly tests, each O(mn(m + n)) per rectangle for the restriction plus
//         O(samples) for the winding; budgets: maxCaps caps and maxCells rectangle tests
//         (past either: not proven, reason budget). Deterministic: the same input gives the
//         same result. Measured (tests/slicing/normal_coverage_test.cpp, default options, Release,
//         2 shared cores): closed C2 tori of 32 bicubic patches 0.05 - 0.07 s, the teapot
//         (32 patches) 0.17 s, its lid 0.84 s, its bottom 0.25 s, its rim 0.02 s.

#include <cstddef>

#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

struct NormalCoverageOptions {
  /// Largest angle (radians) between a rectangle's normals and its centre normal, in
  /// (0, 1]: keeps the chart's distortion and the Lipschitz bounds modest. Caps wider than
  /// this are split without a test. 0.3 doubles the time of 0.6 on the test tori; 0.8
  /// halves it.
  double maxCellSpreadRad = 0.6;
  /// Deepest subdivision of the three cube faces (a face square of side 2 at depth 0; a cap
  /// at depth k has radius about 0.8 2^-k rad), 0 .. 30.
  int maxCapDepth = 16;
  /// Budgets: caps examined and rectangles tested (each >= 1).
  std::size_t maxCaps = 200000;
  std::size_t maxCells = 400000;
};

enum class CoverageOutcome {
  proven,      ///< every direction, up to sign, is a normal
  capDepth,    ///< a cap at maxCapDepth could not be proven
  noPreimage,  ///< no preimage of a cap's centre was found (it may not be a normal at all)
  budget,      ///< maxCaps or maxCells ran out
};

struct NormalCoverage {
  bool proven = false;
  CoverageOutcome outcome = CoverageOutcome::budget;
  std::size_t caps = 0;          ///< caps examined
  std::size_t provenCaps = 0;    ///< caps proven (leaves of the subdivision)
  std::size_t cells = 0;         ///< rectangles tested
  std::size_t skippedCells = 0;  ///< rectangles rejected for |N| not bounded below
  std::size_t samples = 0;       ///< edge samples evaluated
  std::size_t gluedCaps = 0;     ///< caps proven by an assembly of glued rectangles
  int deepestCap = 0;            ///< deepest subdivision level reached
  double smallestCapRad = 0.0;   ///< smallest proven cap's radius (0 if none)
  /// Not proven: the centre of the cap where the proof stopped, and its radius (no claim
  /// that this direction avoids the normals).
  Vec3 unprovenDirection{0.0, 0.0, 0.0};
  double unprovenCapRad = 0.0;
};

/// Tries to prove that every direction m has m or -m among the surface's unit normals (see
/// the contract). Throws scallop::Error on malformed patches or invalid options.
NormalCoverage proveNormalsCoverSphere(const Surface& surface,
                                       const NormalCoverageOptions& options = {});

}  // namespace scallop
