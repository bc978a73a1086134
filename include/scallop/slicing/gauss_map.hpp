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
// Method: Omega is the union of the images of the patches, and of their antipodes; its
//         boundary lies on the images of the patch boundaries and of the parabolic lines
//         (K = 0), as the paper says (the method of Smith & Farouki 2001). A quadtree over
//         each patch, guided by the Bernstein coefficients of the Gaussian curvature
//         numerator (variation diminishing, not a grid), stops at
//         - regular cells, where K keeps a strict sign and the normals vary by less than
//           0.5 rad: the Gauss map is a local diffeomorphism, and the image is the region
//           the images of the cell's four edges bound (with winding);
//         - traced cells, which a parabolic line crosses as one arc that is a graph v(u) or
//           u(v) (K strictly monotone in v, or u, by its coefficients, and at most one root
//           on each edge across): the arc's ends are found on the cell's edges, the arc
//           itself traced by root-finding across the cell, and the cell split along it into
//           its K > 0 and K < 0 parts, each bounded by its edges' images and the arc's (the
//           fold's) image;
//         - small fold cells elsewhere (where parabolic lines meet or touch, or K vanishes on
//           a region), subdivided until their normals vary by less than delta: split along
//           the chord between two crossings, or, failing that, their image taken as the
//           convex hull of their edges' normals.
//         Every curve (cell edges, arcs) is sampled so that the straight polygon edges in the
//         pole frame's plane (for n and for -n) stay within delta of it; neighbouring cells
//         share their edges' vertices exactly. The parts of one patch with one sign of K (a
//         sheet, all of one orientation) are merged by cancelling shared edges, so an edge
//         shared by two cells of the sheets (regular or traced; not a hull, not holding the
//         pole) is sampled at its ends (and crossing) alone: what bounds a sheet is the
//         patch boundary and the parabolic lines. Clipper (libpolyclipping) then unites the
//         sheets, the hulls and the cells whose image holds the pole (the outside of their
//         projected boundary, decided by the membership test below) on an integer grid of
//         2^29 steps across the pole cell's loop, and the complement is what remains inside
//         that loop, shrunk by two grid steps so that no two of its loops touch.
//         Pole: the centre normal of the largest regular cell (with offsetPole, the normal at
//         irrational-looking offsets from its corners: a symmetric surface, such as a surface
//         of revolution, can repeat the centre's normal on other cells' dyadic edges, and the
//         pole on an edge's image sends that polygon through infinity); a traced cell that
//         might hold it is subdivided instead.
// Edges:  the curvature sign is taken from K's numerator with its edge factors split off
//         (bezier.hpp's curvatureSignPolynomial): a parabolic line that runs along a patch
//         edge (a surface of revolution whose profile has an inflection at its end, as the
//         teapot's upper body) is then no fold for the quadtree, and the normal's direction
//         from r_u x r_v with collapsed edges (apexes) factored out (normalDirectionPolynomials):
//         the image of a collapsed edge is the curve of its limit normals (a point for a
//         smooth apex, an arc for a cone's).
// Work:   bounded: at most 2^21 halvings per sampled curve and 2^20 quadtree cells per
//         patch; past them scallop::Error names the patch and the place.
// Coarse band: below delta = 2e-4 / 16 rad, a map at 2e-4 rad comes first, and curves (arcs,
//         patch edges that no other patch touches) farther than 4 coarse tolerances from its
//         boundary are sampled to 2e-4 rad only: they lie deep inside Omega, and their
//         polygons, within 2e-4 rad of them, keep a margin of 2 coarse tolerances from the
//         true boundary, so the union is the same. Patch edges that may be seams are
//         sampled to delta throughout: two patches' polygons of one curve would leave a
//         sliver between them, a gap in Omega as wide as their tolerance. Measured against
//         the map sampled to delta everywhere (3e-4 degree, 7 surfaces): the same boundary
//         to within 0.04 delta, from 30% to 68% of the cell images' vertices. At 100,000
//         segments it leaves about one vertex in six to the union.
// Thin images: beside a parabolic line a sheet can be thinner than delta (a crescent
//         between the fold's image and a patch edge's, tangent where they meet; a spike where
//         the line runs close to a patch edge): the polygons of its sides, each within delta
//         of its curve, may cross, and the lobes they cut off wind the wrong way. Each sheet
//         joins the union as the region its loops wind around either way (nonzero): outside
//         delta of its boundary curves the polygon winds as the curves do (it is homotopic to
//         them within that band), so the region differs from the sheet's image only within
//         delta of normals, and no true normal is lost to the reversed lobes (a random
//         four-patch surface lost a 3 degree spike to them once).
// Accuracy: the polygon is within delta of the true boundary, plus the integer grid's
//         rounding and the 2-step shrink (which only grows Omega). A grid step is 2^-29 of
//         the pole cell loop's extent E in the plane, and up to twice that in angle about the
//         origin (the pole's antipode), where the conformal factor 2 / (1 + |q|^2) is 2: up
//         to ~5 steps there, 2^-26.7 E rad. Measured: E = 24 on paper-1 (~2e-7 rad) and 7.4
//         on paper-2 (~7e-8 rad), so below ~1e-5 degree the tolerance sharpens the boundary
//         everywhere but near the antipodal image. N* and alpha* do not depend on it: they
//         are polished on the true surface and certified (optimal_slicing.hpp).
//         A map whose normals spread less than 2^-24 E (32 steps) would collapse about the
//         origin: it is reported as a point, like a plane's (a bilinear patch 10 km square
//         twisted by 1 mm, spread 1e-7 rad, is one).
// Membership: whether a direction m is a normal (isSymmetrizedNormal) is decided exactly in
//         Bernstein form: whether r_u x r_v is parallel to m (two polynomial equations)
//         with r_u x r_v . m > 0 somewhere on a patch, by subdivision and Newton's method.
// Degenerate surfaces: every normal within delta of one (a plane, or nearly): `kind` point.
//         A patch with K = 0 everywhere (plane, cylinder, developable) has a
//         Gauss image of dimension < 2, the image of its boundary curves. When every patch
//         is such, `kind` tells, and `sphereCurves` describe the image itself, with no
//         loops. Among curved patches a developable patch's normals are obstacles like any
//         other (the slicing direction must keep away from them too): its curves (a point,
//         for a plane) enter Omega as strips of half-width delta / 2 around their polygons,
//         sampled to delta / 2, so that Omega holds them and its boundary stays within
//         delta of them.
// Cost:   O(cells + boundary samples), then the union (Clipper's sweeps over the sheets'
//         loops, one per sheet for its nonzero region, one for the complement, one for the
//         shrinking; some five times faster than Boost.Polygon's at 100,000 segments; past
//         512 pieces, as with thousands of patches, the pieces are united in groups of 16, a
//         tree of unions, before the complement: one sweep over all of them grows with the
//         square of the loops a scanbeam crosses, 244 s for 400 translated copies of paper-1's
//         patch where the tree takes 0.9 s, and 2,000 copies 4.6 s): the
//         boundary samples grow as delta^-1/2 (chords within delta of curves), so
//         ~100,000 boundary segments need delta ~4e-7 degree. On the paper's bicubic surfaces
//         the quadtree stops at some 40 to 90 cells whatever delta is (34 to 48 of them
//         traced); see the README for times.

#include <cstddef>
#include <numbers>
#include <vector>

#include "scallop/slicing/stereographic.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// The finest tolerance accepted, a fixed floor: the union's integer grid resolves 2^-30 of
/// the pole cell loop's extent, which depends on the surface (see Accuracy). ~4e-7 degree
/// (7e-9 rad) gives ~100,000 segments on the paper's surfaces; each tenfold refinement
/// triples them.
inline constexpr double kMinGaussMapToleranceRad = 1e-9;

struct GaussMapOptions {
  double toleranceRad = 0.1 * std::numbers::pi / 180.0;  ///< polygon-to-curve angle, >= kMin...
  /// Deepest quadtree level (cells of 2^-depth in u and v), 1 .. 40: a fold cell stops
  /// there even if its normals still vary by more than the tolerance (a parabolic line
  /// where the normal turns faster than 2^depth * tolerance per unit of u or v).
  int maxCellDepth = 22;
  /// At tolerances finer than 1/16 of 2e-4 rad, sample curves of normals deep inside Omega
  /// (farther than a band around a coarse map's boundary) to the coarse tolerance only.
  bool coarseBand = true;
  /// Take the pole at an off-centre point of its cell (irrational-looking offsets) instead of
  /// the centre: on symmetric surfaces the centre's normal can lie on another cell's edge
  /// image (see the contract, Pole); optimalSlicing retries so when the complement is empty.
  bool offsetPole = false;
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
  /// The boundary of Omega on the unit sphere (original frame), as polylines.
  std::vector<std::vector<Vec3>> sphereCurves;
  std::size_t boundarySegments = 0;  ///< segments in `loops`
  // Statistics.
  std::size_t parabolicCurves = 0;   ///< parabolic lines (connected chains of arcs, per patch)
  std::size_t tracedCells = 0;       ///< quadtree cells where a parabolic arc was traced
  std::size_t foldCells = 0;         ///< small fold cells (normals within the tolerance)
  std::size_t untracedCells = 0;     ///< traced cells whose edges did not show the arc's ends
                                     ///< (subdivided and run again; over every run)
  std::size_t candidatePieces = 0;   ///< cell images united (all curved patches)
  std::size_t imageVertices = 0;     ///< vertices of the cell images' polygons (for n)
  bool coarseBandUsed = false;       ///< curves deep inside Omega sampled coarsely (see
                                     ///< GaussMapOptions::coarseBand)
};

/// The symmetrized Gauss map of `surface` (see the contract above). Throws scallop::Error on
/// a non-positive tolerance.
GaussMap symmetrizedGaussMap(const Surface& surface, const GaussMapOptions& options = {});

/// True when `direction` or its opposite is (up to rounding) a unit normal of the surface.
/// Exact in Bernstein form up to the subdivision's resolution (about 1e-10 in parameter).
bool isSymmetrizedNormal(const Surface& surface, const Vec3& direction);

}  // namespace scallop
