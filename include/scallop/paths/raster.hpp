#pragma once
// Raster (direction-parallel, zigzag) machining with a ball-end cutter: the surface is cut
// by vertical planes along a horizontal feed direction, each section is a monotone chain in
// its plane, and the ball's centre follows the offset of that chain's scallop hull (Chou,
// Woo, Chen, Tang, Shin, "Scallop hull and its offset", CAD 26(7), 1994). The planes are
// spaced as contour.hpp's are (Smith, Farouki, al-Kandari, Pottmann, "Optimal slicing of
// free-form surfaces", CAGD 19, 2002, eq. (3) with a horizontal plane normal), and the best
// feed direction is the one whose plane normal keeps the largest angle alpha to the
// surface normals: the one-dimensional case of that paper's optimal slicing.
//
// Contract
// --------
// Input:  a valid surface (surface.hpp) cut from above (z up, material below); a feed angle a
//         (radians, finite; any value, not reduced) or the request to choose it; a ball
//         radius R > 0; a step-over Delta > 0 between planes, or a scallop height H (then
//         Delta = spacingForScallopHeight(R, H, alpha), alpha below); tolerances (surface
//         units). Feed d = (cos a, sin a, 0), plane normal e = (-sin a, cos a, 0), and in each
//         plane the coordinates (s, z) = (d . r, z): a point is P(s, z) = s d + w e + z z^.
//         When |sin a| < 1e-12 (|cos a| < 1e-12) d and e are snapped to exact +-x, +-y
//         (+-y, +-x), so that arcs lie exactly in their principal plane.
// Planes: e . r = w = planeOffsets[k] when that list is given (cusp.hpp's adaptive spacing);
//         otherwise e . r = w = k Delta for every integer k with w in the control points' range of
//         e . r (the surface lies in their convex hull, so no plane that cuts is missed),
//         in increasing k. A plane whose section has no curve of two or more points
//         (it misses the surface, or only touches it) is skipped.
// Chains: each section curve, as (s, z) at its vertices, must be monotone in s; it is
//         oriented so that s increases. Where the surface is not a graph over the raster
//         direction (a closed section, a curve whose s turns back by more than
//         tau = 1e-9 surfaceScale, or two curves of one plane whose s ranges overlap by more
//         than tau: one sheet above another), with dropEnvelope the plane's chain is what a
//         ball from above sees: the upper envelope over s of its curves, taken at every
//         vertex's s (a crossing of two curves between stations is cut low; the drop
//         envelope lifts the path there), counted in visibleFromAbovePlanes; without it,
//         scallop::Error names the plane offset w, the patch, (u, v) and the point. Back-steps within tau are flattened (s set to
//         the running maximum). Curves of one plane whose s gap g is >= 2R are separate
//         chains, one pass each; curves closer than 2R are merged into one chain through two
//         bridge vertices (s_a, zb), (s_b, zb), zb = min(z_a, z_b) - 2R, at the gap's ends:
//         a ball cannot enter a gap narrower than 2R below the lower rim, so the bridge's
//         floor is never touched and the hull sees exactly the material on both sides
//         (separate passes would each ignore the other side and gouge it within the plane).
// Passes: per chain, scallopHull(chain, R).toolpath: lines and clockwise arcs in (s right,
//         z up) from (s_0 - R, z_0) to (s_n + R, z_n), mapped by P(s, z). The path is exact
//         in its plane: it never comes closer than R to the chain (scallop_hull.hpp).
//         Arcs: for a feed along +-x (+-y) they lie in the zx plane, G18 (yz, G19) and are
//         emitted as arcs. A clockwise turn in (s, z) is a positive rotation about e
//         (d x z^ = -e), so seen from the positive principal axis A it is G2 exactly when
//         e . A < 0: feed +x (e = +y) gives G3, feed -x gives G2, feed +y (e = -x) G2, feed
//         -y G3; reversed passes flip it. Other feeds: the (s, z) path is polygonised with
//         samplePath (path_sampling.hpp) to arcTolerance: a circumscribed polygon, never
//         inside the true path, at most arcTolerance farther from the arc's vertex.
// Zigzag: planes alternate direction: the j-th plane that cuts (from 0) runs toward
//         increasing s for even j, decreasing s for odd j (its chains in decreasing s, each
//         pass reversed: moves in reverse order, arcs' `clockwise` flipped).
// Ends:   a pass's hull path ends R beyond its chain's end at that end's height. Where the
//         surface's boundary is oblique to the feed, that centre lies beside neighbouring
//         parts of the surface that stand higher, and rising straight from it the ball
//         would cut into them. So each end gets a way off: the exit is the hull path's end
//         c itself, or one horizontal line move from c to a point c', after which the
//         centre rises straight to the clear height there, Zc(x, y) = R + a bound on the
//         surface's height within horizontal distance R of (x, y) (above it every centre is
//         at least R from the surface; the bound as the links' Z below); the entry is the
//         same construction at the start, run backwards (from above c' down, then across
//         to c). Proven (not sampled): along the horizontal move and the rise, the depth
//         R - dist(centre, surface) never exceeds max(depth at c, 0) + S, the slack
//         S = max(chordal tolerance, R / 256).
//         Candidates, first proven wins: straight up from c; then c' = c + t R h for t in
//         {1/8, 1/4, 1/2, 3/4, 1, 3/2, 2, 3, 4} and h (horizontal, unit) away from the
//         nearest surface point, along the feed out of the pass, and between the two. The
//         proof is sphere tracing on gouge.hpp's proven lower bound of the distance (a
//         1-Lipschitz function; distance tolerance S / 8): from a centre whose bound exceeds
//         the limit by m, every centre within m is clear. Why S is not just the chordal
//         tolerance: rising from c, where the ball touches the section's end, the distance
//         grows only quadratically, and the steps with it; R / 256 halves the steps.
//         When no candidate is proven (none seen on the paper's surfaces or the tests'
//         random ones), the end rises straight from c and RasterPaths::unclearedEnds counts
//         it. The entry and exit moves are in the pass (RasterPass::entryMoves, exitMoves)
//         and, with the links, in RasterPaths::linkLength.
// Links:  the first pass of each plane after the first feeds from the previous pass's exit
//         point (retractBefore = false; its `start` is that point): straight up to a link
//         height L, across at L, straight down to the pass's entry point; these leading
//         moves are counted in RasterPass::linkMoves (the entry move follows them).
//         L = max(z_exit, z_entry, Z + R), where Z bounds the surface's height over every
//         point within horizontal distance R of the across segment: a ball centre at height
//         >= Z + R there is at least R from each such point, and at least R horizontally
//         from every other. Z comes from branch and bound on sub-patches (each within the
//         convex hull of its control points, so under its box's top) until it is within the
//         chordal tolerance of a surface point in the region (or after kLinkMaxCells cells,
//         still a bound). The vertical moves lie within the proven rises, or above Zc where
//         every centre is clear.
//         Further chains of one plane are entered from the safe height (retractBefore =
//         true), as is the first pass: the G-code's retracts and plunges are vertical at
//         the exit and entry points, proven clear up to Zc and clear above it.
// Gouging: the offset in the section plane rules out gouging within that plane only; the
//         ball may still cut into the surface beside the plane where the surface rises
//         across it (on the paper's surface 1 with R = 0.25 in, 0.19 in deep at pass ends and
//         0.006 in over the part). So, by default (dropEnvelope), every pass, its link, entry
//         and exit included, is then lifted to the drop envelope (envelope.hpp): each vertex
//         straight up to the lowest position where the ball and shank are proven clear,
//         moves halved until each is proven to cut no deeper than depthTolerance (eps); arcs
//         are kept where proven. The passes stay in their planes (lifting is vertical), and
//         RasterPass's move counts, the statistics and linkLength describe the lifted path.
//         The link heights and ways off above were proven for the unlifted ends; lifted, the
//         ends' vertical rises are proven clear by the envelope itself. gouge.hpp measures
//         the deepest interference independently.
// Statistics (PathStats): planes that cut, section components (summed over planes),
//         contactLength (section polyline lengths), centreLength (the cutting moves' true
//         lengths, arcs as arcs, links, entries and exits excluded; after lifting when on);
//         linkLength separately (links, entries and exits).
// Complexity: one planeSection per plane plus O(vertices) per chain for the hull; a link
//         costs at most kLinkMaxCells sub-patch subdivisions (typically tens); a pass end,
//         distance queries: tens when rising straight clears, up to a few thousand when
//         the candidates must be tried.
//         bestRasterAngle: O(patches * G^2) normals once (G = kAngleGrid + 1), a scan of
//         kAngleScan angles at O(patches G^2) each, then golden-section refinement.

#include <cstddef>
#include <vector>

#include "scallop/paths/chain.hpp"
#include "scallop/paths/contour.hpp"
#include "scallop/paths/envelope.hpp"
#include "scallop/paths/scallop_hull.hpp"
#include "scallop/paths/section.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// A section curve's s may step back by this much times surfaceScale (rounding of traced
/// vertices on a vertical wall) before the surface is declared not a graph.
constexpr double kRasterTurnTolerance = 1e-9;
/// Sub-patch cells one link-height bound may subdivide before it settles for its bound.
constexpr std::size_t kLinkMaxCells = 4096;
/// bestRasterAngle: normals on a (kAngleGrid + 1)^2 grid per patch, kAngleScan angles in
/// [0, pi) for the coarse scan.
constexpr int kAngleGrid = 64;
constexpr int kAngleScan = 720;

struct RasterOptions {
  double angleRad = 0.0;    ///< feed angle a: d = (cos a, sin a, 0); unused with bestAngle
  bool bestAngle = false;   ///< true: a = bestRasterAngle(surface), the largest alpha
  double spacing = 0.0;     ///< step-over Delta between planes (> 0), or 0 with scallopHeight
  double scallopHeight = 0.0;  ///< H > 0 with spacing 0: Delta from H and alpha (contour.hpp)
  double toolRadius = 0.0;  ///< R > 0, surface units
  double chordalTolerance = 0.0;  ///< sections (>= 0); 0 means 1e-4 times surfaceScale
  double arcTolerance = 0.0;  ///< polygonised arcs (>= 0); 0 means the chordal tolerance
  /// Lift the passes (links, ways on and off included) to the drop envelope (envelope.hpp):
  /// gouge-free in 3D to depthTolerance. Off: the scallop hull's paths as they are, exact in
  /// their planes only (they cut into the surface where it rises across the plane).
  bool dropEnvelope = true;
  /// eps of the drop envelope (>= 0); 0 means 1e-6 times surfaceScale.
  double depthTolerance = 0.0;  /// Lifts above this are reported as stretches the ball cannot follow (>= 0); 0 means
  /// the envelope's default (10 eps). The CLI passes the scallop height.
  double stretchThreshold = 0.0;
  /// The drop envelope's sag tolerance (envelope.hpp; >= 0, 0: off). The CLI passes H / 4.
  double sagTolerance = 0.0;
  /// Explicit plane offsets w (strictly increasing, finite, at most kMaxPlanes), used instead
  /// of k Delta when non-empty: the planes e . r = planeOffsets[k] (cusp.hpp's
  /// adaptivePlaneOffsets with N = e). Delta (spacing, or from scallopHeight) is then only
  /// reported; spacing and scallopHeight may both be 0.
  std::vector<double> planeOffsets;
};

/// One chain of a plane: what the scallop hull is computed from.
struct RasterChain {
  Chain chain;                      ///< (s, z), s non-decreasing; bridges as in the contract
  std::vector<std::size_t> curves;  ///< indices of its section curves, in increasing s
  ScallopHull hull;                 ///< scallopHull(chain, R)
  std::size_t pass = 0;             ///< index of its pass in RasterPaths::path.passes
};

struct RasterSection {
  double offset = 0.0;  ///< w = k Delta (or planeOffsets[k]): the plane e . r = w
  long long k = 0;      ///< k, or the index into planeOffsets
  PlaneSection section;             ///< planeSection(surface, e, w, chordal tolerance)
  std::vector<RasterChain> chains;  ///< in increasing s
  bool reversed = false;            ///< its passes run toward decreasing s (zigzag)
  /// A plane beyond the outermost given ones (with the drop envelope only; k beyond them):
  /// no chains, its passes are runs of the drop envelope along its line (see the contract).
  bool dropLine = false;
};

/// What one pass of the tool path is.
struct RasterPass {
  std::size_t section = 0;    ///< index into RasterPaths::sections
  std::size_t chain = 0;      ///< index into that section's chains
  bool reversed = false;      ///< runs toward decreasing s
  std::size_t linkMoves = 0;  ///< leading moves that are the link (0 when retracted)
  double linkHeight = 0.0;    ///< L of the link (linkMoves > 0 only)
  /// Moves after the link that lead from the entry point to the hull path's start (0 or 1).
  std::size_t entryMoves = 0;
  /// Trailing moves from the hull path's end to the exit point (0 or 1).
  std::size_t exitMoves = 0;
};

struct RasterPaths {
  double angleRad = 0.0;  ///< the feed angle used (the given one, or bestRasterAngle's)
  Vec3 feedDirection;     ///< d
  Vec3 planeNormal;       ///< e
  /// Proven lower bound on the angle between e and +-(surface normals) (minimumAngleBound).
  double alphaRad = 0.0;
  double spacing = 0.0;   ///< Delta used
  std::vector<RasterSection> sections;  ///< planes that cut, in increasing k
  ToolPath path;                        ///< passes in machining order
  std::vector<RasterPass> passes;       ///< parallel to path.passes
  PathStats stats;
  /// Total length of the moves that do not follow a hull path: links, entries and exits.
  double linkLength = 0.0;
  /// Pass ends (entries and exits) for which no candidate way off was proven clear; each
  /// rises straight from the hull path's end (see the contract).
  std::size_t unclearedEnds = 0;
  /// The drop envelope's lifting (RasterOptions::dropEnvelope; empty when off).
  EnvelopeReport envelope;
  /// Planes where the surface is not a graph over the raster direction, cut along the upper
  /// envelope of their sections (with dropEnvelope; see the contract).
  std::size_t visibleFromAbovePlanes = 0;
};

/// The raster paths of `surface` (see the contract). Throws scallop::Error on bad options
/// (naming the value), without dropEnvelope a surface that is not a graph over the raster
/// direction (naming where), or when no plane cuts the surface.
RasterPaths rasterPaths(const Surface& surface, const RasterOptions& options);

/// The feed angle a in [0, pi) whose plane normal e = (-sin a, cos a, 0) maximises
/// alpha(a), the smallest angle between e and +-n over the surface: the widest step-over
/// for a scallop height. alpha is continuous but only piecewise smooth (a minimum over
/// the surface), so the search is a coarse scan of a sampled estimate, then golden-section
/// refinement of the best local maxima on alpha with every sample's maximum climbed to the
/// true local maximum of |e . n|. Throws scallop::Error on an invalid surface.
double bestRasterAngle(const Surface& surface);

}  // namespace scallop
