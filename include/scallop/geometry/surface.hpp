#pragma once
// Free-form surfaces made of tensor-product Bezier patches: the file format, validation
// (including regularity, r_u x r_v != 0 on the whole patch), and the two bicubic test
// surfaces of Smith, Farouki, al-Kandari, Pottmann, "Optimal slicing of free-form surfaces",
// Section 4.
//
// File format (JSON)
// ------------------
//   {"units": "in" | "mm",
//    "patches": [{"degree": [m, n],
//                 "control_points": [[[x, y, z], ... n + 1 points], ... m + 1 rows]}, ...]}
// control_points[j][k] is the paper's p_jk, the coefficient of b_j^m(u) b_k^n(v) (eq 1):
// row j runs along v. Both keys are required at each level and no other key is accepted (a
// misspelt key is an error, not silently ignored), but for a patch's optional "weights":
// [[w, ... n + 1], ... m + 1 rows], positive numbers shaped as the control points: a
// rational patch (bezier.hpp's Rational patches; every exact cylinder, cone, sphere and
// torus). Coordinates are in the given units.
//
// Contract
// --------
// A valid surface has at least one patch; each patch has degrees 1 <= m, n <=
// kMaxPatchDegree, (m + 1)(n + 1) finite control points whose largest |coordinate| lies in
// [kMinPatchScale, kMaxPatchScale] (or is 0, rejected as singular below), and is regular: with
// scale = the largest |coordinate| of its control points, |q| > tau = 1e-12 scale^2 at every
// (u, v) in [0, 1]^2, where q is r_u x r_v with the factors of collapsed edges split off
// (bezier.hpp's normalDirectionPolynomials: a boundary row or column of the net collapsed to
// one point, an apex as on the Utah teapot's knob and bottom, makes r_u x r_v vanish along
// that edge, and the unit normal there is the limit q / |q|); so that its unit normal (eq 2)
// is defined everywhere, by continuity on such edges. A cone's apex (limits that differ from
// ray to ray) is accepted so too: its normals are those limits. So is a corner where q itself
// vanishes if its direction has a limit along every ray into the patch (two coincident
// corner control points, r_u parallel to r_v at the corner): the patch is then checked as
// the fans of cornerPieces, on which the corner is an apex row. Nets collapsed to a point or
// a line, corners where q vanishes to higher order (no limit along some ray), and interior
// points where q vanishes are rejected.
// A rational patch's weights must be positive and finite, the largest at most
// kMaxWeightRatio times the least; its regularity is decided as a polynomial patch's, on
// N = w^3 r_u x r_v (bezier.hpp), its weights scaled by a power of two to a largest in
// [0.5, 1). Every computation takes rational patches: the Gauss map and the optimal slicing
// on N's polynomials, plane sections on n . X - d w, distances on homogeneous nets, the
// simulated cut's design heights on the homogeneous Jacobian (each module says how).
// Degree 0 in a direction is rejected: r_u or r_v would vanish identically. (Accepted
// patches also satisfy |r_u x r_v| > 1e-12 S_u S_v, above the threshold where bezier.hpp's
// unitNormal throws, so unitNormal never throws on them.)
//
// Regularity (checkPatchRegularity) is decided by a breadth-first quadtree on [0, 1]^2,
// with N = q (r_u x r_v, collapsed edges factored out) and f = |N|^2 in tensor Bernstein
// form (bezier.hpp's normalDirectionPolynomials, bidegree at most (2m-1, 2n-1), and f,
// at most (4m-2, 4n-2)),
// subdivided at cell midpoints by de Casteljau. For each cell:
//   1. proof, f: every Bernstein coefficient of f on the cell exceeds tau^2 + slack_f:
//      f is a convex combination of its coefficients, so |N| > tau on the cell;
//   2. proof, direction: with d the unit normal at the cell's centre, every coefficient of
//      d . N exceeds tau + slack_N: then |N| >= d . N > tau. This is sharper than 1
//      (rounding enters at the level of |N|, not |N|^2) and settles patches whose |N| is
//      tiny somewhere yet well above tau, such as nearly collapsed boundary rows;
//   3. otherwise |r_u x r_v| is evaluated directly at the cell's centre and corners; a value
//      <= tau proves the patch singular there (collapsed boundary rows or columns,
//      collinear control nets, cusps along dyadic lines are found so, at the first cells);
//   4. otherwise the cell is split in four, to depth kRegularityMaxDepth and at most
//      kRegularityMaxCells cells in all. A cell still unresolved then makes the verdict
//      "undecided": |N| comes within rounding of tau near there, or the patch is singular at
//      a non-dyadic point (an isolated zero of N is located only to the cell's size).
//      Undecided patches are rejected as degenerate too, with the location.
// slack_f and slack_N are the rounding errors of the coefficients after `depth` halvings,
// from bernstein.hpp's documented bounds, times 4 (surface.cpp derives them), in terms of
// S_u S_v >= |r_u| |r_v| (S_u = m max|p_{j+1,k} - p_jk|, S_v = n max|p_{j,k+1} - p_jk|): a
// proof is never an artefact of rounding. The check runs on the patch scaled by a power of
// two to scale in [0.5, 1) (exact), so it cannot overflow and its verdict is invariant under
// such scaling.
// Time: O((mn)^2) for the Bernstein forms plus O(mn(m + n)) per cell; c = 1 cell for
// typical patches (the paper's test surfaces: 1 each); a rejected undecided patch costs up
// to kRegularityMaxCells cells (about 0.1 s for a bicubic).
//
// Errors: scallop::Error, the message naming the source ("<stdin>" for "-"), the patch
// index, the row and point index where it applies, and the offending value, e.g.
//   "s.json: patches[1].control_points[2][0]: expected [x, y, z], three finite numbers, got [1,2]".

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "scallop/geometry/bezier.hpp"
#include "scallop/geometry/face_trim.hpp"

namespace scallop {

enum class Units {
  inch,        ///< "in": the paper's test surfaces
  millimetre,  ///< "mm"
};

/// The file's spelling of the units: "in" or "mm".
std::string_view unitsName(Units units);

/// A surface: patches sharing one unit of length. The patches need not join; each is
/// treated on its own (the symmetrized Gauss map of the surface is the union of theirs).
/// Invariant (checked by validateSurface, guaranteed by parseSurface and exampleSurface):
/// see the contract above.
struct Surface {
  Units units = Units::inch;
  std::vector<BezierPatch> patches;
  /// Empty when no patch is trimmed; else one per patch (face_trim.hpp's PatchTrim, without
  /// a face for an untrimmed patch). Trimmed patches come from STEP and IGES faces
  /// (cad_import.hpp's keepTrims); the JSON form has none. A trimmed patch must be regular
  /// where its face is (its pieces are checked where the trim is made, cad_import.cpp), so
  /// validateSurface checks its form only. Sections, distances, the simulated cut's design
  /// and the Gauss map (through trimmed_patch.hpp's pieces) take only the face's part.
  std::vector<PatchTrim> trims{};
  bool trimmed() const { return !trims.empty(); }
  /// Empty, or one per patch (>= 0, surface units): how far the patch's edges may stand off
  /// the neighbouring faces' edges they meet. A CAD model's faces share an edge only to the
  /// model's tolerance (OCCT's BRep_Tool::Tolerance: 1e-7 mm in most files, up to 4e-4 mm on
  /// OCCT's sample parts), so a plane section's curve on one face ends that far from its
  /// continuation on the next. The importer (cad_import.hpp) gives each patch the largest
  /// tolerance of its face and of that face's edges and vertices; section.hpp joins two curve
  /// ends of patches p and q within kSeamJoinFactor max(seam p, seam q) of each other. The
  /// JSON form has none (its patches join exactly).
  std::vector<double> seamTolerances{};
};

/// Patch `patch`'s seam tolerance (Surface::seamTolerances; 0 when there are none).
inline double seamTolerance(const Surface& surface, std::size_t patch) {
  return surface.seamTolerances.empty() ? 0.0 : surface.seamTolerances[patch];
}

/// Largest degree accepted in either direction. It bounds the cost of the regularity check,
/// whose Bernstein form has (4m - 1)(4n - 1) coefficients.
constexpr int kMaxPatchDegree = 20;

/// The largest |coordinate| of a patch's control points must lie in [kMinPatchScale,
/// kMaxPatchScale] (in the file's units). The curvature and certificate polynomials multiply
/// up to a dozen coordinates (or their differences): beyond these they overflow or underflow
/// (measured: 1e-25 and 1e30 work, 1e-30 and 1e300 do not; an error, not a hang, is the
/// answer there). Real parts in inches or millimetres are many orders of magnitude inside.
constexpr double kMinPatchScale = 1e-20;
constexpr double kMaxPatchScale = 1e20;

/// A rational patch's largest weight over its least (bezier.hpp's Rational patches).
constexpr double kMaxWeightRatio = 1e6;

/// Quadtree limits of the regularity check (see the contract).
constexpr int kRegularityMaxDepth = 16;
constexpr std::size_t kRegularityMaxCells = 20000;

/// What the parsers check beyond the text itself.
enum class SurfaceCheck {
  full,      ///< validateSurface: the whole contract above, regularity included (the default)
  formOnly,  ///< only what the text must satisfy: degrees in [1, kMaxPatchDegree], the number
             ///< of control points, finite coordinates. For patches selected before they are
             ///< validated (the CLI's --patches) and for reading data whose regularity is
             ///< judged elsewhere (tests of the built-in examples' files).
};

/// Parses and validates a surface from JSON text; `sourceName` (a file name, or "-" for
/// standard input) is used in error messages.
Surface parseSurface(std::string_view json, const std::string& sourceName,
                     SurfaceCheck check = SurfaceCheck::full);


/// The surface as JSON in the file format, one row of control points per line. Numbers are
/// written shortest-round-trip (-0 as -0.0), so parseSurface(surfaceToJson(s)) reproduces
/// every coordinate bit for bit. Deterministic. Writes any surface whose patches have
/// degrees >= 0 and the matching number of finite control points (regularity is not
/// checked) and no trims (they have no JSON form); throws scallop::Error otherwise.
std::string surfaceToJson(const Surface& surface);

/// Throws scallop::Error ("patches[i]...: ...") unless `surface` satisfies the contract.
void validateSurface(const Surface& surface);

/// The same, the message prefixed with `sourceName` ("s.json: patches[i]...: ...").
void validateSurface(const Surface& surface, const std::string& sourceName);

enum class RegularityVerdict {
  regular,    ///< |r_u x r_v| > tau proven on all of [0, 1]^2
  singular,   ///< found (u, v) with |r_u x r_v| <= tau
  undecided,  ///< neither, within the quadtree limits (treated as degenerate)
};

/// The outcome of the regularity check of one patch.
struct PatchRegularity {
  RegularityVerdict verdict = RegularityVerdict::regular;
  double u = 0.0;  ///< singular / undecided: where (the least |r_u x r_v| seen)
  double v = 0.0;
  double relativeNormalLength = 0.0;  ///< |r_u x r_v| / scale^2 at (u, v)
  double threshold = 1e-12;           ///< tau / scale^2: singular if relativeNormalLength <= this
  std::size_t cells = 0;  ///< quadtree cells examined (1 when f's coefficients are positive)
};

/// Decides whether a patch is regular (see the contract). The patch must have degrees >= 1
/// and (m + 1)(n + 1) finite control points.
PatchRegularity checkPatchRegularity(const BezierPatch& patch);

/// tau / scale^2 of the contract: |q| <= tau is a zero of q.
constexpr double kRelativeNormalTolerance = 1e-12;

/// A piece of a patch (cornerPieces): its own Bezier patch, and where its parameters land on
/// the source patch's.
///
/// A corner where q vanishes while its direction has a limit along every ray into the patch
/// (q = (u - u_c) q_u + (v - v_c) q_v + ..., cos(theta) q_u + sin(theta) q_v != 0 on the
/// quadrant: two coincident control points p00 = p01, or r_u parallel to r_v there) is
/// blown up: the rectangle is cut along its diagonal through the corner into two fans, each
/// reparametrized polynomially so that the corner becomes a collapsed edge (an apex row), on
/// which q's direction is the limit along each ray. For the corner (0, 0):
///   beside the edge v = 0: (a, t) -> (u, v) = (a, a t),  r(a, a t), bidegree (m + n, n);
///   beside the edge u = 0: (s, b) -> (u, v) = (b s, b),  r(b s, b), bidegree (m, m + n);
/// their Jacobians a and b are positive inside, so the orientation (the normal's sign) is
/// kept, and r_a x r_t = a (r_u x r_v)(a, a t) = a^2 (q_u + t q_v + O(a)): two edge factors
/// that normalDirectionPolynomials divides out, leaving the ray limits on the apex row.
/// The other corners are mirror images, with t or s reversed to keep the orientation.
struct PatchPiece {
  BezierPatch patch;
  std::size_t source = 0;  ///< the source patch's index in its surface
  /// The rectangle of the source's [0, 1]^2 the piece lies in: the whole patch, or a quarter
  /// when several corners are blown up (one per quarter).
  double u0 = 0.0, u1 = 1.0, v0 = 0.0, v1 = 1.0;
  /// -1: the piece is the rectangle itself. Else the rectangle's blown-up corner (bit 0 set:
  /// u = u1, bit 1 set: v = v1), and which fan: the one beside the rectangle's edge through
  /// the corner along u (besideUEdge, parameters (a, t)) or along v (parameters (s, b)).
  int corner = -1;
  bool besideUEdge = false;
  /// The source's (u, v) at the piece's parameters (s, t) in [0, 1]^2.
  Vec2 sourceParameters(double s, double t) const;
};

/// The patch as pieces without corners where q vanishes: {the patch itself} when it has
/// none (the usual case, a copy); else two fans about its one such corner, or its four
/// quarters (halved at 1/2, shared edges bit for bit equal) with the two fans about each
/// quarter's corner that is one of them. The pieces cover the patch exactly (up to rounding
/// of their control points) and share its unit normals: n_piece(s, t) = n(sourceParameters(s,
/// t)), on a fan's apex row the limit along the ray. Corners are found as in the regularity
/// check (|q| <= tau there). Throws scallop::Error for a malformed patch, and when a corner
/// must be blown up but m + n > kMaxPatchDegree (the fans' degree). Time: O((m + n)^2 n^3)
/// per fan, O((mn)^2) to look for corners.
std::vector<PatchPiece> cornerPieces(const BezierPatch& patch, std::size_t source = 0);

/// Every patch of `surface` replaced by its cornerPieces, in order; `sources`, if given,
/// receives each piece's source patch index. Every algorithm that needs the unit normal's
/// direction field on the closed patch (the Gauss map, the coverage proof, the optimal
/// slicing's polish and certificate) works on these pieces.
Surface cornerResolved(const Surface& surface, std::vector<std::size_t>* sources = nullptr);

/// The trim of patch `patch`, or nullptr when it is not trimmed.
inline const PatchTrim* patchTrim(const Surface& surface, std::size_t patch) {
  return surface.trimmed() && surface.trims[patch].trimmed() ? &surface.trims[patch] : nullptr;
}

/// Whether the point (u, v) of patch `patch` belongs to the surface: always for an untrimmed
/// patch, inside its face or on a trimming curve for a trimmed one (face_trim.hpp's
/// keepsPoint). Samplers of patches skip the points it refuses.
inline bool surfaceKeepsPoint(const Surface& surface, std::size_t patch, double u, double v) {
  const PatchTrim* trim = patchTrim(surface, patch);
  return trim == nullptr || keepsPoint(*trim, u, v);
}

/// A trimmed surface's patches as pieces that follow their faces (trimmed_patch.hpp's
/// splitTrimmedPatch against each patch's trim, classifyCell): inside and boundary pieces, so
/// their normals hold every normal of the faces (a superset within the pieces' spread); an
/// untrimmed patch as it is. The result has no trims. For the Gauss map and the optimal
/// slicing (a certified lower bound of alpha* over the faces). Throws scallop::Error past
/// the options' budget of pieces, per patch.
Surface trimmedPieces(const Surface& surface, const TrimSplitOptions& options = {});

/// The largest |coordinate| over all control points (0 for no patches): the length scale
/// for tolerances.
double surfaceScale(const Surface& surface);

/// The highest z of all control points (-inf for no patches): the convex-hull property makes
/// it an upper bound of the surface (safe heights, the stock's top).
double controlPointTop(const Surface& surface);

/// Names of the built-in example surfaces, and one of them by name (throws on an unknown
/// name). All are in inches. The bicubic test surfaces of the paper's Section 4, on a
/// 3 x 3 inch footprint with p_jk = (k, j, z_jk):
///   "paper-1"  test surface #1 (Section 4.1, Fig. 1); the paper's optimum
///              N* = (0.248, -0.969, 0.001), eq (18);
///   "paper-2"  test surface #2 (Section 4.2, Fig. 8), symmetric under p_jk <-> p_kj;
///              N* = (0.975, -0.221, -0.002), eq (19).
/// The Utah teapot (Newell 1975; POV-Ray 3.7's teapot.inc, see the README), 32 bicubic
/// patches in the standard order, z up, 3.15 in tall, and its natural parts (patch indices of
/// "teapot"):
///   "teapot"          all 32 patches;
///   "teapot-rim"      0-3;    "teapot-body"    4-11 (upper 4-7, lower 8-11);
///   "teapot-handle"   12-15;  "teapot-spout"   16-19;
///   "teapot-lid"      20-27 (knob 20-23, lid 24-27);  "teapot-bottom"  28-31.
/// The knob's patches 20-23 and the bottom's 28-31 have their row p_0k collapsed to one point
/// (the apex on the axis), where r_v = 0: they are not regular in the sense of the contract
/// above, and exampleSurface does not validate.
/// The same surfaces are in examples/surfaces/<name>.json (paper-1, paper-2, teapot; also
/// teapot.bpt), each part being a range of teapot.json's patches.
std::vector<std::string> exampleSurfaceNames();
Surface exampleSurface(const std::string& name);

}  // namespace scallop
