#pragma once
// The symmetrized Gauss map of a surface (Smith, Farouki, al-Kandari, Pottmann, "Optimal
// slicing of free-form surfaces", 2002, Section 3.1; the method of Smith & Farouki 2001).
//
// Contract
// --------
// Input:  a surface of regular Bezier patches (see surface.hpp) and an angular tolerance
//         delta > 0 (radians).
// Output: the symmetrized Gauss map Omega (every unit normal n of the surface and its
//         antipode -n) described by its boundary, a set of polygons that approximate the
//         true boundary within delta (angle on the unit sphere), in two forms:
//         - on the sphere (original frame), for figures;
//         - in the stereographic plane (eq 5) of a rotated frame whose north pole is a
//           surface normal `pole` (so that no circle in the complement of Omega passes through
//           the pole, and the complement's image is bounded): closed loops, the complement of
//           Omega being the points inside an odd number of loops (even-odd rule).
// Method: the boundary of the Gauss image of a patch lies on the images of the patch
//         boundary curves and of its parabolic lines (K = 0), the zero set of the Gaussian
//         curvature numerator (a bivariate Bernstein polynomial), isolated by a quadtree on
//         which the coefficients (variation diminishing) decide which cells may hold it, and
//         traced where one partial derivative keeps its sign. These candidate curves (and
//         their antipodes) are cut at their intersections, and a piece is kept as boundary
//         when the points just beside it, on its two sides, differ in belonging to Omega.
//         Membership of a direction m is decided exactly in Bernstein form: whether
//         r_u x r_v is parallel to m (two polynomial equations) with r_u x r_v . m > 0
//         somewhere on a patch, by subdivision and Newton's method.
// Degenerate surfaces: a patch with K = 0 everywhere (plane, cylinder, developable) has a
//         Gauss image of dimension < 2; `kind` tells, and the boundary curves then describe
//         the image itself (`sphereCurves`), with no loops.
// Cost:   O(candidate points + intersections + pieces * membership test); the membership
//         test is a subdivision of degree (2m-1, 2n-1) polynomials.

#include <cstddef>
#include <numbers>
#include <vector>

#include "scallop/stereographic.hpp"
#include "scallop/surface.hpp"
#include "scallop/vector.hpp"

namespace scallop {

struct GaussMapOptions {
  double toleranceRad = 0.1 * std::numbers::pi / 180.0;  ///< polygon-to-curve angle, > 0
  int parabolicMaxDepth = 10;  ///< quadtree depth for the parabolic lines (cells of 2^-depth)
};

enum class GaussMapKind {
  region,  ///< Omega has interior: `loops` bound it
  curve,   ///< K = 0 on every patch: Omega is a set of curves (`sphereCurves`)
  point,   ///< all normals equal (a plane): Omega is {pole, -pole}
};

struct GaussMap {
  GaussMapKind kind = GaussMapKind::region;
  Vec3 pole{0.0, 0.0, 1.0};  ///< a surface normal (original frame), mapped to the north pole
  Rotation3 toPoleFrame;      ///< rotation taking `pole` to (0, 0, 1)
  /// The boundary of Omega in the stereographic plane of the pole frame: closed loops (the
  /// last point joins the first). The complement of Omega is the even-odd interior.
  std::vector<std::vector<Vec2>> loops;
  /// Boundary pieces that did not close into loops (empty unless the extraction met a
  /// tangency it could not resolve; the loops are then incomplete).
  std::vector<std::vector<Vec2>> openChains;
  /// The boundary of Omega on the unit sphere (original frame), as polylines.
  std::vector<std::vector<Vec3>> sphereCurves;
  std::size_t boundarySegments = 0;  ///< segments in `loops`
  std::size_t parabolicCurves = 0;   ///< traced parabolic-line polylines (all patches)
  std::size_t candidatePieces = 0;   ///< candidate pieces after cutting at intersections
  std::size_t membershipTests = 0;   ///< directions tested for membership in Omega
};

/// The symmetrized Gauss map of `surface` (see the contract above). Throws scallop::Error on
/// a non-positive tolerance.
GaussMap symmetrizedGaussMap(const Surface& surface, const GaussMapOptions& options = {});

/// True when `direction` or its opposite is (up to rounding) a unit normal of the surface.
/// Exact in Bernstein form up to the subdivision's resolution (about 1e-10 in parameter).
bool isSymmetrizedNormal(const Surface& surface, const Vec3& direction);

}  // namespace scallop
