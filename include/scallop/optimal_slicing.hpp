#pragma once
// The optimal slicing orientation of a free-form surface (Smith, Farouki, al-Kandari,
// Pottmann, "Optimal slicing of free-form surfaces", CAGD 2002, Sections 3.2-3.4).
//
// Contract
// --------
// Input:  a surface of regular Bezier patches (surface.hpp) and an angular tolerance for the
//         Gauss map's polygonal boundary (radians).
// Output: the unit normal N* of parallel slicing planes N . r = k Delta that maximises, over
//         the whole surface, the minimum angle alpha between N and +-n (n the surface
//         normal), with alpha* itself; the maximal circle that realises it, in the
//         stereographic plane of the Gauss map's pole frame and on the sphere; and a
//         certificate: a Bernstein-form proof, patch by patch, that no surface normal lies
//         within alpha* - margin of +-N* (margin = 1e-7 rad, which keeps the subdivision
//         shallow; alpha* itself is exact to rounding, see Accuracy).
// Method: symmetrized Gauss map Omega (gauss_map.hpp) -> stereographic projection with a
//         surface normal as the pole (eqs 5-7) -> medial axis of the projected complement of
//         Omega (medial_axis.hpp; the map's loops first cleaned of zero-width zigzags, see
//         below) -> along every medial-axis edge, tan(alpha) = 2R / (rho^2 - R^2 + 1) (eq 12)
//         at the edge's ends and at the roots in (0, 1) of eq (13), built in Bernstein form
//         with R^2 for R (degree 4 for linear edges, 8 for parabolic ones) -> the best circle
//         gives N* by eq (14), rotated back from the pole frame -> the polish: from that
//         circle and up to three rivals within 4 tolerances of it (more than a degree apart),
//         and from the four best of a lattice of 2,000 directions (a safety net against a
//         Gauss map that misses normals, which the medial axis cannot see; the medial axis's
//         seeds win ties), the minimax problem min_N max |n . N| is solved on the true
//         surface by a trust-region SQP method: the contacts (local maxima of |n . N| over
//         each patch, interior, on an edge or at a corner) by Newton's method from warm
//         starts and a fixed 33 x 33 grid per patch; the step from a QP in 3 unknowns (the
//         tangent step and the level t) over the linearised contacts with the Lagrangian's
//         curvature, solved exactly by enumerating active sets; quadratic convergence where
//         the optimum is a vertex of three contacts or an edge of two (the derivation is in
//         the source). The best polished direction is N*.
// Accuracy: the circle is exact for the polygonal Omega, which lies within the tolerance of
//         the true boundary; N* and alpha* are then those of a local optimum of the true
//         problem, to rounding (|n . N*| to ~1e-16; N* to ~1e-8 where the optimum is an edge
//         of two contacts, along which max |n . N| grows only quadratically). The tolerance
//         only chooses the basin; alpha* is non-decreasing and N* constant once it is fine
//         enough (the paper's surfaces: from 1 degree on). The certificate states what is
//         proven.
// Zigzags: the Gauss map's polygon union can return a loop that runs back and forth over a
//         few grid steps, and sliver holes (seen at fine tolerances with the earlier
//         cell-union Gauss map); the medial axis rejects those, so vertices where a loop
//         turns back within a triangle thinner than 1% of the tolerance are removed, and
//         loops of negligible area dropped, before it (the boundary moves by less than that).
// Cost:   the paper's bicubic surfaces at 0.5 degree: ~24 ms (paper-1) and ~29 ms
//         (paper-2) of CPU, of which the Gauss map 8 / 11 ms and the medial axis 7 / 6. At
//         ~100,000 boundary segments (5e-7 degree on both): ~10 s / ~14 s, the Gauss map
//         ~4 s / ~9 s and the medial axis ~5 s (Boost's Voronoi falls back to its
//         multiprecision predicates on the finely sampled, nearly collinear boundary).
// Degenerate surfaces: a plane (Omega two points) gives alpha* = 90 degrees with N* any
//         direction orthogonal to the normal (one is returned); for a surface whose Gauss
//         image is a curve (K = 0) the result is found by maximising the minimum angle over
//         the curve's sampled normals directly (flagged by `method`).

#include <cstddef>
#include <numbers>
#include <string>
#include <vector>

#include "scallop/gauss_map.hpp"
#include "scallop/stereographic.hpp"
#include "scallop/surface.hpp"
#include "scallop/vector.hpp"

namespace scallop {

struct OptimalSlicingOptions {
  /// Gauss-map polygon tolerance, in (0, 0.1) rad. 0.5 degree gives 120-160 boundary
  /// segments on the paper's surfaces (the paper used a few hundred); N* is polished on the
  /// true surface afterwards, so a finer tolerance changes it only when it moves the medial
  /// axis to another basin. ~5e-7 degree gives ~100,000 segments on either surface.
  double toleranceRad = 0.5 * std::numbers::pi / 180.0;
  bool certify = true;  ///< run the Bernstein-form certificate
};

struct OptimalSlicing {
  Vec3 normal;             ///< N*, unit (its sign is arbitrary: +-N* slice alike)
  double alphaRad = 0.0;   ///< alpha*: the minimum angle between N* and +-n, radians
  PlaneCircle circle;      ///< the maximal circle in the pole frame's stereographic plane
  SphereCircle sphereCircle;  ///< the same circle on the unit sphere (original frame)
  Vec3 pole;               ///< the surface normal used as the pole
  bool certified = false;  ///< proven: no normal within certifiedAlphaRad of +-N*
  double certifiedAlphaRad = 0.0;  ///< the angle the certificate proves (alpha* - 1e-7 rad)
  std::size_t certificateCells = 0;  ///< quadtree cells the certificate examined
  std::string method = "medial-axis";  ///< "medial-axis", "plane" or "curve"
  GaussMap gaussMap;
  /// The interior medial axis of the projected complement (pole frame), each edge sampled
  /// as a polyline, for figures.
  std::vector<std::vector<Vec2>> medialAxisCurves;
  std::size_t medialAxisEdges = 0;
  int medialAxisRebuilds = 0;
  double seconds = 0.0;    ///< wall time of the whole computation
};

/// The optimal slicing orientation of `surface`; throws scallop::Error on bad options.
OptimalSlicing optimalSlicing(const Surface& surface, const OptimalSlicingOptions& options = {});

/// The minimum angle (radians) between direction `n` (any length) and +-(surface normals),
/// proven at least `lowerBoundRad` when the return is true: the Bernstein-form certificate
/// (see the contract), subdividing each patch while needed, up to `maxDepth`. `cells`
/// counts the cells examined.
bool certifyClearance(const Surface& surface, const Vec3& n, double lowerBoundRad,
                      std::size_t& cells, int maxDepth = 14);

}  // namespace scallop
