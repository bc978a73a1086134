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
//         Patches whose r_u x r_v vanishes somewhere (an apex: a collapsed boundary row) are
//         accepted: the cells where the lower bound on |r_u x r_v| fails are skipped, and
//         the other cells are used. Malformed patches (degree < 1, wrong control count)
//         throw scallop::Error, as do invalid options.
// Output: NormalCoverage. proven == true is a proof (rigorous up to the floating-point
//         rounding bounds stated below) that every direction m has m or -m among the unit
//         normals n = N / |N|, N = r_u x r_v, of the patches on [0, 1]^2. proven == false
//         names a direction whose cap could not be proven (not a claim that it is uncovered).
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
//         Rectangles are chosen, not searched blindly: Newton's method on g(s n(u, v)) = 0
//         from the parent cap's preimages (first) and from a fixed 4 x 4 grid of seed cells
//         per patch whose normal cone holds c (when those fail) finds the preimages of c, and rectangles centred there (moved inside
//         the patch) are tried at sizes from the chart Jacobian's smallest singular value;
//         any heuristic failure costs completeness, never soundness. A cap not proven is
//         split in four, to maxCapDepth; a cap at that depth, or a centre with no preimage
//         found, ends the proof with that direction reported.
// Rounding: the restricted Bernstein coefficients carry bernstein.hpp's bounds
//         (gamma_{6m} + gamma_{6n} of the largest |coefficient| of N, times 4), which are
//         subtracted from the lower bounds and added to the derivative bounds; the sampled
//         chart points carry eps (their evaluation error through 1 / |N| and the chart,
//         times 4); the cap's radius is rounded up. Those are the "stated rounding".
// Limits: a direction whose every preimage lies on a patch boundary (a seam of a G1
//         surface: on a convex closed surface every direction has one preimage, so the seams'
//         images), on a fold (a parabolic line, where the Gauss map is not locally onto), or
//         only at points where N = 0 cannot be proven by single-patch rectangles; closed
//         surfaces whose patches' normals overlap across seams (each seam direction also
//         normal inside some patch) and whose extreme points are not degenerate are proven.
// Complexity: per cap O(P) for the seed cones (P patches) plus a few Newton solves and
//         rectangle tests, each O(mn(m + n)) for the restriction plus O(samples) for the
//         winding; budgets: maxCaps caps and maxCells rectangle tests (past either: not
//         proven, reason budget). Deterministic: the same input gives the same result.
//         Measured (tests/normal_coverage_test.cpp, default options): closed C2 tori of 32
//         bicubic patches 0.13 - 0.17 s (2,500 - 3,500 caps), 35 patches 0.05 s.

#include <cstddef>

#include "scallop/surface.hpp"
#include "scallop/vector.hpp"

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
