#pragma once
// A trimmed face's domain in its parameter plane: the trimming curves (the pcurves of its
// edges) as exact rational Bezier arcs, and where boxes and points of the plane lie with
// respect to them (issue 14, item 3: "the trimming curves are honoured everywhere").
// OpenCASCADE-free: cad_import.cpp converts a face's pcurves into arcs; everything here is
// plain geometry, so that the Gauss map, sections, distances and the simulated cut can all
// classify against the same curves.
//
// Contract of mayMeet
// -------------------
// Input:  an arc of n >= 1 homogeneous poles (w u, w v, w), every w > 0 and finite, and a box.
// Output: false only when the arc provably misses the box: a rational arc with positive
//         weights lies in the convex hull of its poles, so in their box, and so does each
//         piece of it (de Casteljau on the homogeneous poles). true once a piece whose poles'
//         box meets the box is smaller than an eighth of the box in both directions, or at
//         depth 40: conservatively "may meet". Rounding of the pieces' poles is a few ulps
//         of the poles a step, so at most some hundreds at depth 40; callers widen their
//         boxes by far more (cad_import.cpp: 1e-8 of the face's rectangle).
// Method: Bezier clipping (Sederberg and Nishita 1990) on the box's four sides: u >= u0 on
//         the arc is the Bernstein polynomial with coefficients w u - u0 w (w > 0) being
//         >= 0, which the convex hull of its control points confines to an interval of the
//         parameter. The piece on the four intervals' common part goes on when that part is
//         at most half the piece, else the piece's two halves do; an empty part proves a
//         miss. So each step at least halves a piece's parameter interval (depth k: length
//         at most 2^-k), and a piece crossing or passing near the box converges to it
//         quadratically instead of by one halving a level.
// Work:   at most 2^k pieces examined for the depth k reached, k <= 40; O(n^2) each (n
//         poles). On the trimmed disk's plan (three rational quadratic arcs, cells down to
//         2^-18 of the patch) about 4 steps (clips or halvings) a call that gets past the
//         arc's pole box, where halving alone took 18.
//
// Contract of classifyPoint
// -------------------------
// Input:  a face's trim: its arcs forming closed loops in the parameter plane (each edge's
//         pcurve in the direction its wire runs, seam edges once in each direction; ends of
//         consecutive arcs may differ by the model's tolerance), and a point p.
// Output: inside or outside by the parity of the winding number of the loops about p (odd:
//         inside; so a hole's loop, whichever way it runs, takes p out again), boundary when
//         p lies on an arc or within rounding of one, or when the arcs' angles about p do not
//         sum to a multiple of 2 pi within kWindingSlackRad (a gap between the ends of
//         consecutive arcs that p is close to beside its size).
// Method: each arc's angle about p, exactly up to rounding: an arc whose poles (as vectors
//         from p) lie in a wedge narrower than pi lies in it too (convex hull), so its angle
//         is its end's angle from its start, atan2(a x b, a . b); otherwise it is halved
//         (de Casteljau on the homogeneous poles), at most kWindingDepth times.
// Work:   O(n) per arc far from p (n poles); an arc passing near p at distance d halves
//         O(log(size / d)) times along its length near p.
//
// classifyBox: boundary when some arc may meet the box (mayMeet), else its centre's place
// (a box that no arc meets lies wholly on one side: its centre tells which; a centre the
// winding cannot decide makes the box boundary).

#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "scallop/geometry/trimmed_patch.hpp"

namespace scallop {

/// A box [u0, u1] x [v0, v1] of a face's parameter plane (closed).
struct ParameterBox {
  double u0 = 0.0, u1 = 0.0, v0 = 0.0, v1 = 0.0;
  bool meets(const ParameterBox& other) const {
    return u0 <= other.u1 && other.u0 <= u1 && v0 <= other.v1 && other.v0 <= v1;
  }
};

/// The most poles an arc may have (OCCT's curves are of degree 25 at most).
inline constexpr std::size_t kMaxTrimPoles = 32;

/// One rational Bezier arc of a trimming curve in a face's parameter plane: its poles in
/// homogeneous coordinates (w u, w v, w), w > 0, from the arc's start to its end.
using TrimArc = std::vector<std::array<double, 3>>;

/// The box of the arc's poles (u = wu / w, v = wv / w).
ParameterBox poleBox(const TrimArc& arc);

/// Whether the arc may meet the box (see the contract: false is proven). Throws
/// scallop::Error for an arc of no poles or more than kMaxTrimPoles.
bool mayMeet(const TrimArc& arc, const ParameterBox& box);

namespace detail {
/// mayMeet by halving alone, without the clipping (its method until 2026-12): the same
/// contract, kept as the peer of scallop-bench's BM_TrimMayMeet and checked by the same test.
bool mayMeetByHalving(const TrimArc& arc, const ParameterBox& box);
}  // namespace detail

/// A trimmed face's domain: the arcs of its trimming loops (see classifyPoint's contract).
struct FaceTrim {
  std::vector<TrimArc> arcs;
};

/// How far the arcs' angles about a point may sum from a multiple of 2 pi (radians).
inline constexpr double kWindingSlackRad = 0.1;
/// Halvings of an arc before a point is taken to lie on it.
inline constexpr int kWindingDepth = 60;

/// The angle (radians) the arc sweeps about (u, v); NaN when (u, v) lies on it (within
/// rounding: kWindingDepth halvings did not separate it).
double sweptAngle(const TrimArc& arc, double u, double v);

/// Where the point (u, v) lies with respect to the face's trim (see the contract).
CellPlace classifyPoint(const FaceTrim& trim, double u, double v);

/// Where the box lies with respect to the face's trim (see the contract).
CellPlace classifyBox(const FaceTrim& trim, const ParameterBox& box);

/// One of a face's parameters as a function of one of its patch's, x in [0, 1], monotone.
/// The other patch parameter does not enter: the faces this serves are B-spline and Bezier
/// faces (a patch is a knot span of the face's own parameters) and the kinds OCCT converts to
/// rational B-splines as tensor products (cylinders, cones, spheres, tori, revolutions: u the
/// angle about the axis, v along the generatrix).
///  - affine: from + x (to - from).
///  - halfAngle: middle + 2 atan((x - 1/2) / (slope x + offset)), radians: the angle of a
///    point of a circular arc given as a rational quadratic Bezier curve with parameter x.
///    Why this form: every proper parametrisation of a conic by rational quadratics is a
///    linear fractional (Moebius) reparametrisation of any other, in particular of the
///    standard q -> ((1 - q^2), 2 q) / (1 + q^2) with q = tan(angle / 2); and tan((a - m) / 2)
///    is itself a Moebius function of tan(a / 2). So tan((angle - middle) / 2) is a Moebius
///    function of x that vanishes at x = 1/2, (x - 1/2) / (slope x + offset), fixed by the
///    angles at the ends (halfAngle(from, middle, to)). It is monotone on [0, 1] when its
///    denominator keeps one sign there (validateAxisMap).
/// cad_import.cpp fits the map through x = 0, 1/2 and 1 and checks it at the seven inner
/// eighths against OpenCASCADE's own parameters of the patch's points.
struct AxisMap {
  enum class Kind { affine, halfAngle };
  Kind kind = Kind::affine;
  double from = 0.0, to = 1.0;                     // the values at x = 0 and x = 1
  double middle = 0.0, slope = 0.0, offset = 0.0;  // halfAngle: the value at 1/2, the denominator
  double at(double x) const;
  static AxisMap affine(double from, double to);
  /// The arc's angles (radians) at x = 0, 1/2 and 1; each end within pi of the middle and on
  /// the other side of it from the other end (else not a monotone arc: throws Error).
  static AxisMap halfAngle(double from, double middle, double to);
};

/// Throws Error (naming `what`) unless the map is finite, not constant and monotone on [0, 1].
void validateAxisMap(const AxisMap& map, const char* what);

/// A Bezier patch of a trimmed face: the face's trim, shared by its patches, and the map from
/// the patch's parameters (s, t) in [0, 1]^2 to the face's, u = u.at(s), v = v.at(t) (each
/// decreasing where the patch runs against the face's parameter, as a REVERSED face's patches
/// do). Without a face the patch is not trimmed. The patch is the part of its square whose
/// image lies in the face (classifyPoint: inside, or on a trimming curve). A cell of the
/// square maps onto the box of its corners' images (each map monotone).
struct PatchTrim {
  std::shared_ptr<const FaceTrim> face;
  AxisMap u, v;
  /// Boxes are widened by this in the face's parameters before they are classified: the
  /// rounding of the map and of the arcs' halving (cad_import.cpp: 1e-8 of the face's
  /// rectangle).
  double margin = 0.0;
  bool trimmed() const { return face != nullptr; }
};

/// Where the cell of the patch's square lies with respect to its face (classifyBox of the
/// cell's image widened by the margin); inside for a patch that is not trimmed.
CellPlace classifyCell(const PatchTrim& trim, const ParameterCell& cell);

/// Whether some arc of the patch's face may meet the cell's image widened by the margin
/// (mayMeet: false is proven); false for a patch that is not trimmed. classifyCell is
/// boundary when this holds, else the place of the image's centre.
bool cellMayMeetTrim(const PatchTrim& trim, const ParameterCell& cell);

/// Where the point (s, t) of the patch's square lies with respect to its face (classifyPoint
/// of its image); inside for a patch that is not trimmed. A cell for which cellMayMeetTrim is
/// false lies wholly on one side of the trim (a closed box no arc meets is connected): any of
/// its points, its corners included, gives its place, as its centre does (short of a gap
/// between arcs' ends that the winding cannot close, where either may be boundary).
CellPlace placeOfPoint(const PatchTrim& trim, double s, double t);

/// Whether the point (s, t) of the patch's square belongs to the patch's part of its face:
/// inside or on a trimming curve (classifyPoint's boundary); true for an untrimmed patch.
bool keepsPoint(const PatchTrim& trim, double s, double t);

}  // namespace scallop
