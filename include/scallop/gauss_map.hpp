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
// Method: Omega is the union of the images of small pieces of the patches, and of their
//         antipodes; its boundary then lies on the images of the patch boundaries and of
//         the parabolic lines (K = 0), as the paper says. A quadtree over each patch,
//         guided by the Bernstein coefficients of the Gaussian curvature numerator
//         (variation diminishing), stops at regular cells, where K keeps a strict sign and
//         the normals vary by less than 0.5 rad (the Gauss map is a local diffeomorphism
//         there: the image is the region bounded by the images of the cell's four edges),
//         and at fold cells, across a parabolic line, subdivided until their normals vary
//         by less than delta (the image: the convex hull of their edges' normals). The pole
//         is the centre normal of the largest regular cell; everything outside that cell's
//         projected boundary is in Omega, so each image is clipped to a square around it.
//         Cell edges are sampled so that the straight polygon edges in the pole frame's
//         plane (for n and for -n) stay within delta of the curves, and so that
//         neighbouring cells share their edges' vertices exactly. The cells of one patch
//         with one sign of K (a sheet, all of one orientation) are merged by cancelling
//         shared edges; Boost.Polygon unites the sheets, the fold cells and the cells whose
//         image holds the pole (the outside of their projected boundary, decided by the
//         membership test below) on an integer grid of 2^29 steps across the pole cell's
//         loop, and the complement is what remains inside that loop.
// Membership: whether a direction m is a normal (isSymmetrizedNormal) is decided exactly in
//         Bernstein form: whether r_u x r_v is parallel to m (two polynomial equations)
//         with r_u x r_v . m > 0 somewhere on a patch, by subdivision and Newton's method.
// Degenerate surfaces: a patch with K = 0 everywhere (plane, cylinder, developable) has a
//         Gauss image of dimension < 2, the image of its boundary curves. When every patch
//         is such, `kind` tells, and `sphereCurves` describe the image itself, with no
//         loops. Among curved patches a developable patch's normals are obstacles like any
//         other (the slicing direction must keep away from them too): its curves (a point,
//         for a plane) enter Omega as strips of half-width delta / 2 around their polygons,
//         sampled to delta / 2, so that Omega holds them and its boundary stays within
//         delta of them.
// Cost:   O(cells x edge samples) for the images, then the union (Boost's sweep over the
//         sheets' loops, the fold cells and the strips). The paper's bicubic surfaces at
//         0.5 degree: ~55 ms (paper-1) and ~120 ms (paper-2). At ~100,000 boundary segments
//         (paper-1 at 0.0033 degree: 150,000 cells, a third of them fold cells) Boost's
//         difference takes about two thirds (its input: ~100,000 fold-cell hulls, mutually
//         overlapping, and the sheets' ~200,000 edges), the quadtree and the edge sampling
//         most of the rest (each cell evaluates 5 new normals, its corners coming from its
//         parent; each edge piece is sampled once for its two cells).

#include <cstddef>
#include <numbers>
#include <vector>

#include "scallop/stereographic.hpp"
#include "scallop/surface.hpp"
#include "scallop/vector.hpp"

namespace scallop {

struct GaussMapOptions {
  double toleranceRad = 0.1 * std::numbers::pi / 180.0;  ///< polygon-to-curve angle, > 0
  /// Deepest quadtree level (cells of 2^-depth in u and v), 1 .. 40: a fold cell stops
  /// there even if its normals still vary by more than the tolerance (a parabolic line
  /// where the normal turns faster than 2^depth * tolerance per unit of u or v).
  int maxCellDepth = 22;
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
  // Statistics (their names, kept for the JSON output, come from an earlier method).
  std::size_t parabolicCurves = 0;   ///< fold cells (quadtree cells across a parabolic line)
  std::size_t candidatePieces = 0;   ///< cell images united (all curved patches)
  std::size_t membershipTests = 0;   ///< always 0: the cell union needs no membership tests
};

/// The symmetrized Gauss map of `surface` (see the contract above). Throws scallop::Error on
/// a non-positive tolerance.
GaussMap symmetrizedGaussMap(const Surface& surface, const GaussMapOptions& options = {});

/// True when `direction` or its opposite is (up to rounding) a unit normal of the surface.
/// Exact in Bernstein form up to the subdivision's resolution (about 1e-10 in parameter).
bool isSymmetrizedNormal(const Surface& surface, const Vec3& direction);

}  // namespace scallop
