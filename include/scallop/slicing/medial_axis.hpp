#pragma once
// Medial axis transform (MAT) of a polygonal planar domain, with the radius function of
// every edge in the closed forms of the optimal-slicing paper (Optimal slicing of free-form
// surfaces, sections 3.3-3.4, eqs (15)-(17)), built on Boost.Polygon's Voronoi diagram of
// segments.
//
// Contract
// --------
// Input:  a PlanarDomain: closed polygonal loops (the last point joins the first). The domain
//         is the set of points inside an odd number of loops (even-odd rule): an outer loop
//         with holes, islands inside holes, several components. Loop orientation is free.
//         Checked, with scallop::Error: at least one loop; every coordinate finite; after the
//         clean-up below every loop keeps >= 3 points and a non-zero area; no loop folds back
//         on itself (a zero-width spike); no two segments touch or cross except consecutive
//         segments of one loop at their shared point (an exact test on the integer
//         coordinates, O(n log n)); no loop or point outside the integer range (fixed
//         gridStep only).
//         Clean-up (not an error): consecutive points that coincide on the integer grid are
//         merged, and a point that continues its neighbours' straight line exactly (on the
//         grid) is dropped; neither changes the boundary as a set.
//         Assumed, not checked beyond the above: the loops are what they claim to be, i.e.
//         features closer than about one grid step q (below) are not distinguished.
// Output: the interior medial axis: every edge of the Voronoi diagram of the boundary
//         segments and their end points that lies inside the domain, as a linear or parabolic
//         MedialEdge with its two boundary sites and its radius function R(t), t in [0, 1]:
//           line/line   (two segments):  straight, R(t) = [d0 (1-t) + d1 t] sin(psi)  eq (15)
//           point/point (two vertices):  straight, R(t) = sqrt([d0 (1-t) + d1 t]^2 + h^2) (16)
//           point/line  (a reflex vertex and a segment): a parabolic arc, a quadratic Bezier
//                                         curve r(t), R(t) = |r(t) - f|, f the focus     (17)
//         Included: the edges that end at convex vertices (radius 0 there; the paper's
//         Section 3.3 notes them). Excluded: the Voronoi edges outside the domain, the infinite
//         ones, the secondary ones (between a segment and its own end point: the normals at
//         reflex vertices, on which nothing of the MAT changes), and edges shorter than
//         1e-3 q. Edges come in Boost's order (deterministic for a given input and options).
//         Control points and radii are in the caller's units and frame.
// Time:   O(n log n) for n boundary segments (Boost's sweep line, the intersection and
//         orientation checks, and the validation with a bounding-volume hierarchy); O(n)
//         memory. 100,000 segments sampling two circles: ~2.5 s of CPU on the development
//         machine, 70-80% of it in Boost's sweep, whose multiprecision fallback serves most
//         circle events of finely sampled curves (nearly parallel consecutive segments);
//         two exactly regular 50,000-gons (nearly cocircular vertices) or a wavy annulus of
//         the same size ~3.5 s.
//
// Integer scaling (Boost's input must be integral; its docs state the 32-bit range)
// ------------------------------------------------------------------------------------
// The domain is rotated (MedialAxisOptions::rotationRad, about its bounding-box centre),
// its bounding box is centred on the origin and scaled so that its larger half-side is
// 2^29 grid steps, and every point is rounded to the nearest integer (with
// MedialAxisOptions::gridStep > 0: rotation about the origin and that step instead). The step
// q = (larger half-side) / 2^29 ~ 1.9e-9 of the domain's size; 2^29 rather than 2^31 keeps
// every orientation test of the checks exact in 64-bit integers. Rounding moves every
// boundary point by at most q / sqrt(2), so the medial axis built is that of a domain within
// Hausdorff distance 0.71 q of the input. The edges' radius functions are exact for their
// sites (the rounded features mapped back to the caller's frame), and
//     |radiusAt(e, t) - clearance(domain, pointAt(e, t))| <= MedialAxis::tolerance = q,
// the 0.29 q beyond the rounding covering floating-point error (~1e-14 of the domain's size)
// and Boost's vertex error (a fixed relative precision: its own diagram merges vertices
// within 128 ulps, ~1.5e-5 q). Points of the medial axis lie
// inside the domain or within the tolerance of its boundary.
//
// Validation and rebuilds (Boost's known failures)
// ------------------------------------------------
// Boost.Polygon's Voronoi builder has rare, reported failures: a missing vertex and wrong
// edges on valid integer input (boostorg/polygon#43, open: a six-point polygon, reproduced
// here with Boost 1.74 and replayed by the tests), an infinite edge starting inside a closed
// polygon (#72, open), and a hang (#49, open: an endless loop in voronoi_diagram::_build()
// while it removes degenerate vertices, on 1,912 segments passed as doubles, outside the
// integer contract; removing any one segment avoids it). #32 ("diagram broken") turned out
// to be touching segments, i.e. invalid input. Here:
//  - the hang cannot occur: the sweep line feeds a small edge recorder of this module
//    instead of boost::polygon::voronoi_diagram, so _build()'s rot_next walks never run
//    (the sweep itself terminates: every step consumes a site event or a circle event, and
//    circle events are only created with new arcs); and the input meets Boost's contract
//    (integers, no zero-length segments, no touching or crossing segments);
//  - every diagram is validated before use: each edge's two sites agree on which side of
//    the boundary it lies; no infinite edge starts strictly inside; no vertex inside the
//    domain is a dead end; the medial axis has one connected piece per component of the
//    domain (one per loop at even nesting depth); at t = 0, 1/2, 1 of every kept edge the
//    point lies inside the domain and its radius equals its clearance from the input
//    boundary, computed independently of Boost (checkMedialAxis). On failure the
//    input is rotated by a further sqrt(2) - 1 rad (incommensurable with pi/2, so axis-
//    aligned input never returns to the axes), quantised again and rebuilt, up to
//    maxRebuilds times; then scallop::Error explains the last failure.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "scallop/geometry/vector.hpp"

namespace scallop {

/// Closed polygonal loops; the domain is the set of points inside an odd number of them.
struct PlanarDomain {
  std::vector<std::vector<Vec2>> loops;
};

/// A boundary feature of the domain: a vertex, or a segment a -> b with the domain on its
/// left (loops are re-oriented so that this holds whatever the input orientation).
struct MedialSite {
  enum class Kind {
    point,    ///< a (reflex or convex) vertex; b == a
    segment,  ///< the segment a -> b, domain on the left
  };
  Kind kind = Kind::point;
  Vec2 a;
  Vec2 b;
};

/// One edge of the medial axis, parameterised by t in [0, 1] (the paper's Section 3.4 form
/// (x(t), y(t), R(t))).
struct MedialEdge {
  enum class Kind {
    linear,     ///< the segment control[0] -> control[1] (control[2] == control[1])
    parabolic,  ///< the quadratic Bezier curve control[0], control[1], control[2]
  };
  /// Which pair of sites the edge bisects; selects the radius function.
  enum class Bisector {
    lineLine,    ///< two segments; eq (15); linear
    pointPoint,  ///< two vertices; eq (16); linear
    pointLine,   ///< siteA a vertex (focus), siteB a segment (directrix); eq (17); parabolic
  };
  Kind kind = Kind::linear;
  Bisector bisector = Bisector::lineLine;
  /// Bezier control points. Parabolic: control[1] is the intersection of the tangents at
  /// the two ends.
  std::array<Vec2, 3> control{};
  double radiusStart = 0.0;  ///< R(0): the clearance at control[0]
  double radiusEnd = 0.0;    ///< R(1): the clearance at the last control point
  MedialSite siteA;          ///< the two boundary features the edge is equidistant from
  MedialSite siteB;
  /// lineLine: distances of the two ends from the intersection of the sites' lines, with
  /// R(t) = [d0 (1-t) + d1 t] sinPsi, 2 psi the angle between the lines. Parallel lines
  /// (R constant) are stored as d0 = radiusStart, d1 = radiusEnd, sinPsi = 1.
  /// pointPoint: signed distances of the two ends from the midpoint of the two vertices,
  /// along the bisector, with R(t) = sqrt([d0 (1-t) + d1 t]^2 + halfGap^2).
  /// pointLine: unused (0).
  double d0 = 0.0;
  double d1 = 0.0;
  double sinPsi = 0.0;   ///< lineLine only
  double halfGap = 0.0;  ///< pointPoint only: h = |a - b| / 2
};

struct MedialAxis {
  std::vector<MedialEdge> edges;
  int rebuilds = 0;                  ///< rotated rebuilds needed after failed validations
  std::size_t boundarySegments = 0;  ///< segments handed to Boost (after the clean-up)
  double quantum = 0.0;              ///< grid step q of the accepted build, caller's units
  double tolerance = 0.0;            ///< radius/clearance tolerance (= q, see the contract)
  double rotationRad = 0.0;          ///< rotation of the accepted build
};

struct MedialAxisOptions {
  /// Rotation (radians, counter-clockwise) applied to the domain before it is quantised;
  /// the output is rotated back. Rebuilds add sqrt(2) - 1 rad each.
  double rotationRad = 0.0;
  /// Rotated rebuilds tried after a diagram fails validation, before scallop::Error.
  int maxRebuilds = 3;
  /// 0: automatic integer scaling (see the contract). > 0: the grid step in the caller's
  /// units, with integer coordinates round(x / gridStep) about the origin (rotations too are
  /// about the origin), so that an integer input is handed to Boost exactly as given (to
  /// replay a reported input). Every rotated |coordinate| / gridStep must stay below 2^29.
  double gridStep = 0.0;
};

/// The medial axis transform of `domain` (see the contract at the top of this header).
/// Throws scallop::Error on invalid input or when every rebuild fails validation.
MedialAxis medialAxis(const PlanarDomain& domain, const MedialAxisOptions& options = {});

/// Point of the edge at parameter t (de Casteljau on the control points).
Vec2 pointAt(const MedialEdge& edge, double t);

/// Radius of the maximal disc centred at pointAt(edge, t), by eq (15), (16) or (17).
double radiusAt(const MedialEdge& edge, double t);

/// Distance from p to the domain's boundary (all loops' segments), brute force O(n): the
/// reference checker for tests.
double clearance(const PlanarDomain& domain, Vec2 p);

/// Whether p lies inside an odd number of loops (even-odd crossing count, O(n)). Points on
/// the boundary may go either way.
bool insideDomain(const PlanarDomain& domain, Vec2 p);

/// What checkMedialAxis found.
struct MedialAxisCheck {
  bool ok = true;
  std::size_t checkedPoints = 0;
  std::size_t failures = 0;
  double worstRadiusError = 0.0;  ///< max |radiusAt - clearance|, and of the site distances
  double worstOutside = 0.0;      ///< max distance of a sample outside the domain (0: none)
  std::string firstFailure;       ///< a readable description of the first failure
};

/// Invariant checker, independent of Boost: at `samplesPerEdge` (>= 2) evenly spaced t of
/// every edge, pointAt lies inside the domain (or within axis.tolerance of its boundary),
/// its radius equals its clearance from the boundary and its distance to each of the two
/// sites, within axis.tolerance. Clearances come from a bounding-volume hierarchy over the
/// domain's segments: O((n + m samplesPerEdge) log n) for m edges on average.
MedialAxisCheck checkMedialAxis(const PlanarDomain& domain, const MedialAxis& axis,
                                int samplesPerEdge = 3);

}  // namespace scallop
