#pragma once
// Plane sections of a surface of Bezier patches: every component of {r(u, v) : N . r = d},
// closed loops and curves ending on the surface's boundary, traced to a chordal tolerance.
// They are the contact loci of contour machining (Smith, Farouki, al-Kandari, Pottmann,
// "Optimal slicing of free-form surfaces", eq. (3): planes N . r = k Delta) and the
// sections that raster machining feeds to the scallop hull.
//
// Contract
// --------
// Input:  a valid surface (surface.hpp), a plane N . r = d (N finite and non-zero; it is
//         normalised, d is then scaled by 1/|N|), a chordal tolerance eps > 0 (surface units).
// Output: the section as polylines whose vertices lie on the surface with their patch and
//         (u, v), and on the plane to rounding (|N . r - d| <= ~1e-14 scale) except at
//         junctions (below), which lie within a junction cell of the tangent point; edges
//         deviate from the true curve by at most about eps (checked at the quarter points
//         of every edge). Pieces from different cells and patches are joined where their
//         ends meet (within kJoinTolerance scale), so a closed section comes back as one closed loop and a
//         section running across patch edges as one curve. On a CAD model's patches, whose
//         faces meet only to the model's tolerance (surface.hpp's seamTolerances), ends of two
//         patches join within kSeamJoinFactor times the larger of their tolerances, but never
//         farther apart than eps (so the joining chord is as close to the curve as the traced
//         ones): a section crossing a seam between faces is one curve, not two that stop there. `components` counts the connected
//         pieces (a junction where several branches meet, as at a saddle tangent to the plane,
//         is one component).
// Method (why it is robust where the plane is tangent): f(u, v) = N . r(u, v) - d is a
//         tensor Bernstein polynomial of the patch's bidegree, with coefficients N . p_jk - d
//         (on a rational patch, w f = N . X - d w with coefficients w_jk (N . p_jk - d): the
//         same zeros and signs, as w > 0; its points are r = X / w).
//         A quadtree on [0, 1]^2 drops a cell when f's coefficients there are all >= 0 or all
//         <= 0 (then f has no zero inside the open cell; zeros on its edges belong to the
//         neighbours, and patch boundary edges lying in the plane are added whole), and
//         accepts it as "simple" when f_v (or f_u) has
//         coefficients of one strict sign: then f is monotone in v, the zero set in the cell is
//         a graph v = g(u) over the u-intervals where f(u, v0) and f(u, v1) differ in sign, and
//         those intervals end at roots of f on the cell's edges (isolated in Bernstein form).
//         Elsewhere the cell is split, at 0.4959 of its width rather than at one half, so
//         that a section running along a dyadic parameter line does not lie on cell edges at
//         every depth. Only where grad f vanishes on the zero set (the plane
//         tangent to the surface: an isolated touch point, a saddle crossing) does the split
//         reach kSectionMaxDepth; such a cell becomes a junction: its edge crossings are joined
//         at its centre (a touch point with no crossings is reported in `touchPoints`). Roots
//         on a cell edge come from the whole iso-parameter line, computed once, so two cells
//         sharing an edge agree on its crossings bit for bit.
// Trimmed: a trimmed patch (surface.hpp's trims) gives only the parts of its pieces inside
//         its face: each traced piece is cut where its vertices change side (face_trim.hpp's
//         keepsPoint: inside or on a trimming curve), the crossing found by 48 halvings of
//         the chord in (u, v) between the two vertices, each point brought back onto the
//         section by Newton steps along f's gradient, so a curve's end lies on the section
//         and within about 2^-48 of the chord from the trimming curve. Touch points outside
//         the face are dropped. A patch whose square lies outside its face is skipped.
// Complexity: O(c (mn)^2) for c quadtree cells, plus O(1) evaluations per traced vertex
//         (each a 1-D safeguarded Newton solve); c grows like the number of section pieces
//         and the log of the inverse distance to tangency.

#include <cstddef>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// Split depth at which a cell where the plane is (nearly) tangent becomes a junction:
/// cells of about 2^-18 in each parameter.
constexpr int kSectionMaxDepth = 18;
/// Ends of pieces closer than this times the surface scale are the same point.
constexpr double kJoinTolerance = 1e-9;

/// Curve ends on two patches of a CAD model are joined within this many times the larger of
/// the patches' seam tolerances (surface.hpp's seamTolerances): the two faces' edges each
/// stand within the tolerance t of their shared edge, so a plane crossing the seam at an angle
/// theta on the surface meets them up to 2 t / sin(theta) apart along it: 16 t joins them
/// down to theta = 7.2 degrees at the full tolerance (the gaps of real files are mostly far
/// below their declared tolerance), and the chordal tolerance caps it (section's contract).
constexpr double kSeamJoinFactor = 16.0;

struct SectionPoint {
  Vec3 point;              ///< r(u, v)
  std::size_t patch = 0;   ///< which patch of the surface
  double u = 0.0;
  double v = 0.0;
};

struct SectionCurve {
  std::vector<SectionPoint> points;  ///< in order; a closed loop repeats its first point last
  bool closed = false;
};

struct PlaneSection {
  std::vector<SectionCurve> curves;
  std::size_t components = 0;     ///< connected pieces (curves meeting at a junction count once)
  std::vector<SectionPoint> touchPoints;  ///< isolated points where the plane touches the surface
  std::size_t cells = 0;          ///< quadtree cells examined (all patches)
};

/// The section of `surface` by the plane normal . r = offset (see the contract).
PlaneSection planeSection(const Surface& surface, const Vec3& normal, double offset,
                          double chordalTolerance);

/// Length of a polyline through the curve's points.
double curveLength(const SectionCurve& curve);

}  // namespace scallop
