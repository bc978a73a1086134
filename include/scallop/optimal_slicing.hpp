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
//         within alpha* - margin of +-N* (margin = the tolerance plus a rounding allowance).
// Method: symmetrized Gauss map Omega (gauss_map.hpp) -> stereographic projection with a
//         surface normal as the pole (eqs 5-7) -> medial axis of the projected complement of
//         Omega (medial_axis.hpp) -> along every medial-axis edge, tan(alpha) = 2R / (rho^2 -
//         R^2 + 1) (eq 12) at the edge's ends and at the roots in (0, 1) of eq (13), built in
//         Bernstein form with R^2 for R (degree 4 for linear edges, 8 for parabolic ones) ->
//         the best circle gives N* by eq (14), rotated back from the pole frame.
// Accuracy: alpha* is exact for the polygonal Omega; the polygon lies within the tolerance
//         of the true boundary, so alpha* is within about the tolerance of the true optimum,
//         and converges as the tolerance shrinks. The certificate states what is proven.
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
  /// Gauss-map polygon tolerance. 0.5 degree gives a few hundred boundary segments on the
  /// paper's surfaces, as the paper used; N* is polished on the true surface afterwards, so
  /// a finer tolerance changes it only when it moves the medial axis to another basin.
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
  double certifiedAlphaRad = 0.0;  ///< the angle the certificate proves (alpha* - margin)
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
