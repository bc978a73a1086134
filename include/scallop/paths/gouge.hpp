#pragma once
// Gouge check: how deep does the ball-end cutter, its centre moving along a tool path, cut
// into the whole surface? The raster strategy offsets each pass from the surface's section
// by a vertical plane, which rules out gouging within that plane only; this module measures
// the interference of the ball with every patch, and so the gap to a fully gouge-free path.
// Its kernel is the Euclidean distance from a point to a surface of Bezier patches.
//
// Contract: distance to the surface
// ---------------------------------
// Input:  a surface of Bezier patches (surface.hpp: degrees 1 .. kMaxPatchDegree, (m + 1)
//         (n + 1) finite control points each; regularity is not needed here; rational patches
//         with positive weights within kMaxWeightRatio, see Rational below) and a finite
//         point p, in the surface's units.
// Output: the minimum of |r(u, v) - p| over every patch and (u, v) in [0, 1]^2, boundary
//         included, as a point that attains the returned distance (patch, u, v, r(u, v)) and
//         a proven lower bound:  lowerBound <= true distance <= distance, and
//         distance - lowerBound <= tolerance  (converged; see the early exit below). So the
//         returned distance is within `tolerance` of the true minimum, from above.
// Method: branch and bound over sub-patches (cells). Lower bounds of a cell, the largest
//         kept, all from the convex hull property (a sub-patch lies in the convex hull of
//         its control points):
//         1. the distance from p to the axis-aligned box of its control points;
//         2. a separating plane: min_i (c_i - p) . w over its control points c_i, w the unit
//            direction from p to the cell (the mean of its corners). Why: an axis-aligned
//            box of a tilted cell of size h is O(h) thick along the normal, so bound 1 lags
//            the distance by O(h) and a tolerance t would take O(1/t) cells; along w, which
//            tends to the normal near the foot point, the net is O(h^2) thin;
//         3. convexity: where f = |r - p|^2 / 2 is provably strongly convex on the cell
//            (the Hessian's smallest eigenvalue bounded below by lambda > 0 from interval
//            products of the boxes of the cell's first and second derivative nets), f >=
//            f(x0) + grad f(x0) . (x - x0) + lambda/2 |x - x0|^2 on the whole cell,
//            minimised over the cell in closed form, x0 the best point so far clamped into
//            the cell. Why: bounds 1 and 2 still need about log4(1/t) levels to close the
//            gap; this one is exact up to rounding at the foot point once the cell is small
//            enough for f to be convex on it (the paper's surface #1 at distance 0.25:
//            after one or two splits). Farther than the focal distance (p beyond a centre of
//            curvature) f is not convex and bounds 1 and 2 carry the search alone.
//         Upper bounds are surface points: the corners of every cell (corner control
//         points), the centre of every cell taken from the queue, and, whenever that centre
//         improves on the best so far, a projected Newton iteration on f clamped to
//         [0, 1]^2 from there. The cell with the smallest lower bound is split in four (de
//         Casteljau at 1/2 in u and v) until no cell can beat the best point by more than
//         the tolerance. The patches' boxes are kept in a bounding-volume hierarchy (median
//         splits along the longest axis, at most kPatchesPerLeaf patches a leaf, in index
//         order), whose nodes are queued by the same lower bounds as cells: a patch's cells
//         enter the search only when its leaf's box can beat the best point, so a query near
//         one region of a part of thousands of patches (a trimmed face's pieces) looks at
//         O(log N) nodes, not at every patch. A surface of at most kPatchesPerLeaf patches
//         is one leaf, its patches offered in order as before.
//         Each patch's quadtree of cells to `treeDepth` levels is built once,
//         with its boxes (the halving is bezier.hpp's subdivideU then subdivideV at 1/2, bit
//         for bit, without allocation); the search starts from it and halves its leaves
//         further on demand. Cells halved below the trees are kept per thread across queries
//         (keyed by patch, depth and position; at most 1024 splits, emptied at a query's
//         start when full or when another SurfaceDistance queried on that thread last), so
//         consecutive queries in one region (the drop envelope's proofs along a pass) reuse
//         their nets and boxes instead of halving again. They are computed as the search
//         would compute them, so every result is the same, bit for bit, whatever is kept.
// Pieces: a cell is halved in u and v together, so on a long thin patch (a fillet along an
//         edge, a strip) the cells stay as long and thin as the patch, and near a contact the
//         search must halve the short way far below the size the long way needs: paper-1's
//         patch stretched 100 times along x took 8 times as long to plan as when cut into 64
//         pieces by hand. So each patch is first cut at 1/2 (bezier.hpp's subdivideU or V,
//         u halvings first) along the longer way of its control net (the longest control
//         polygon that way) until that way is at most twice the other, at most
//         kMaxPieceHalvings times a way; each piece is searched as a patch (its own quadtree,
//         its root box in the hierarchy), and results name the original patch and its
//         parameters (the pieces span [k, k + 1] / 2^j, so the map back is exact). A piece's
//         net carries the rounding of its halvings: the allowance counts them as cell depth,
//         with the original patch's scale and weight ratio. A patch whose ways are within a
//         factor 2 (the paper's surfaces, the teapot's patches) is one piece, unchanged.
// Trimmed: a trimmed patch (surface.hpp's trims) counts only where its face is. Its cells
//         are classified against the face's trimming arcs (face_trim.hpp's cellMayMeetTrim,
//         then for a cell no arc meets placeOfPoint at its corner at its parent's centre,
//         which its siblings share; kept per thread): outside, dropped; inside, kept with no
//         more classifying; on a trimming curve, split like any cell but to kTrimCellDepth
//         at most, their lower bounds (of the whole cell) standing there. Upper bounds are
//         points of the face only (keepsPoint on every corner, centre and Newton point).
// Rational: a rational patch's cells keep their Euclidean control points (the cell lies in
//         their convex hull, as the weights are positive) and weights; halving works on the
//         homogeneous points w p and the weights, and divides back. Bounds 1 and 2 hold as
//         for a polynomial net; bound 3 is not used (the derivatives are quotients, not
//         differences of the net), so the search near a foot point takes a few more levels;
//         the rounding allowance is multiplied by 2 w_max / w_min + 1 (the quotient's error,
//         each part's relative to w_max, divided by w >= w_min). Points and derivatives by
//         bezier.hpp's quotient rule.
// Early exit: with a cutoff c, cells whose lower bound is >= c are dropped too (nothing
//         below c there). Then either the result is converged as above, or lowerBound >= c
//         (the true distance is at least c; `distance` is then the best point seen, perhaps
//         infinity). The gouge check passes c = max(the least distance so far, R - depth
//         threshold): most samples are settled by a few boxes of the quadtree.
// Tolerance: absolute, in the surface's units; 0 selects 1e-9 x surfaceScale(surface).
//         Rounding: every lower bound is lowered by an allowance for the rounding of the
//         subdivided control points (bernstein.hpp: gamma_{3n} per halving) and of the box
//         distances, (3 (m + n) (depth + 1) + 16) u (scale + |p|_inf), u = 2^-53: about
//         1e-13 of the coordinates, far below the default tolerance; the convexity bound's
//         lambda is lowered by 1e-12 of the magnitudes of its terms (its interval products
//         are not rounded outwards; their errors are a few ulps). A tolerance below that
//         allowance cannot be met: the search then stops at kMaxCellDepth halvings or at
//         maxCells cells and reports converged == false with the bounds it has proven.
// Complexity: building, O(4^treeDepth (m + 1)(n + 1)) memory and time per patch
//         (bicubic, depth 4: 341 cells, 130 kB, about 0.1 ms), the depth lowered for all
//         patches alike until their trees hold at most kTreePointsBudget control points in
//         all (22,862 bicubic pieces of a trimmed part: depth 1, 43 MB, not 3 GB), plus
//         O(N log N) for the hierarchy. A query: O(m n (m + n)) per
//         cell; on the paper's surface #1 at distance 0.25, 7.4 cells on average, about 10^5
//         queries per second of one core (at distance 2, beyond the focal distance in
//         places: 50 cells, 3 x 10^4 per second). Worst case maxCells cells: at a centre of
//         curvature of a nearly spherical concave region (every cell nearly as close, f not
//         convex), or with a tolerance near the rounding allowance. A ball of radius R that
//         fits the concave regions (R below their radii of curvature) keeps its centres
//         inside the focal distance, where bound 3 applies. Queries are const and
//         thread-safe (scratch space and the kept cells are per thread: about 1.7 MB for
//         each of the two searches with bicubic patches, held until the thread ends).
//
// Contract: gouge check
// ---------------------
// Input:  the surface and a tool path (toolpath.hpp: ball centres, radius R = toolRadius > 0,
//         the same units as the surface, finite positions, arcs in principal planes whose
//         two ends lie at the same distance from the centre, up to 1e-6 of the radius), a
//         sample spacing s > 0 (finite, path length units).
// Sampling: every cutting move of every pass, and the straight link from the previous pass's
//         end to a pass's start when retractBefore == false, is sampled at every vertex and
//         at equal steps of at most s of path length in between (arcs as arcs: equal angle
//         steps). Rapid moves (retract, traverse, plunge) are not checked: they are the
//         strategy's business, above the material.
// Output: for each sample c, depth(c) = R - dist(c, surface): positive where the ball cuts
//         into the surface, by that much along the common normal. The report gives the
//         largest depth (signed, and clamped at 0), where it happens (pass, move, centre,
//         contact point on the surface, patch and (u, v)), the number of samples, and how
//         many are deeper than a threshold (samples whose computed depth > threshold).
// Between samples: dist(., surface) is 1-Lipschitz and every centre of the path lies within
//         s/2 of a sample along the path (the step between samples is at most s), so the
//         true largest depth over the whole continuous path is at most
//         depthBound = R - (least proven lower bound of a sample's distance) + maxSampleGap / 2
//         (reported), which is <= signedMaxDepth + tolerance + maxSampleGap / 2 when every
//         query converged; maxSampleGap <= s is the largest step actually used. Computed
//         depths err low by at most the tolerance (the distance is an upper bound).
// Centres inside the material: R - dist understates the interference of a ball whose centre
//         lies below the surface. The path is continuous within a pass (and its link), so a
//         centre can only get below by crossing the surface, where a sample within s/2 has
//         depth >= R - s/2; the check therefore tests each retracted pass's first centre and
//         counts those below the surface (passStartsBelowSurface: on the side opposite to
//         the upward normal at the closest point). With that count 0 and signedMaxDepth <
//         R - s/2, no sample lies inside the material.
// Errors: scallop::Error for s not positive and finite, R not positive and finite, units
//         differing from the surface's, non-finite positions, degenerate arcs (zero radius,
//         a full circle, ends at different distances from the centre), or more than
//         maxSamples samples (a tiny spacing on a long path); the message names the value
//         and, for the path, the pass and move.
// Complexity: O(path length / s + number of moves) samples, each one distance query.
// Threads: the samples are taken in fixed blocks of consecutive moves (about
//         kGougeSamplesPerBlock samples each, cut where the path says, never where a thread
//         count says), each block with its own early-exit state, on every core
//         (GougeOptions::threads); the blocks' reports are combined in path order (the first
//         deepest sample wins a tie). The report is the same for any number of threads.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

namespace detail {
struct PatchTree;  // one patch's quadtree of sub-patches and their boxes (gouge.cpp)
struct PatchNode;  // a node of the hierarchy of the patches' boxes (gouge.cpp)
}  // namespace detail

/// Deepest halving of a cell below the patch: a cell then spans 2^-48 in u and v, and its
/// corners stay exact binary fractions.
constexpr int kMaxCellDepth = 48;
/// A trimmed patch's cells on its trimming curves are split to this depth at most (cells of
/// 2^-18 of the patch): their lower bounds then stand, so distances beside a trimming curve
/// are resolved to about kTrimCellReach of the surface's scale (a closest point converges
/// within tolerance + that; a segment clearance a cell there would decide is undecided).
/// Why not deeper: where the face's nearest point lies on a trimming curve, the cells whose
/// bounds (of the whole cell, the outside part included) stay below it number about
/// h^-1/2 at side h (measured on paper-1 trimmed to a disk: depth 26 took 125 ms a query).
constexpr int kTrimCellDepth = 18;
constexpr double kTrimCellReach = 4.0 / (1 << 18);

/// Patches per leaf of SurfaceDistance's hierarchy of patch boxes.
constexpr std::size_t kPatchesPerLeaf = 8;
/// Control points in all the patches' prebuilt trees (24 bytes each): the trees' depth is
/// lowered below DistanceOptions::treeDepth past it.
constexpr std::size_t kTreePointsBudget = std::size_t{1} << 22;
/// A long thin patch is cut into at most 2^kMaxPieceHalvings pieces along its long way (see
/// the contract's Pieces), and a surface into at most kPiecesBudget pieces (or its patch
/// count, when more): past it every patch's halvings are capped alike.
constexpr int kMaxPieceHalvings = 7;
constexpr std::size_t kPiecesBudget = std::size_t{1} << 16;

struct DistanceOptions {
  /// Absolute tolerance on the distance (surface units, >= 0); 0 selects 1e-9 x the
  /// surface's scale (surfaceScale).
  double tolerance = 0.0;
  /// Levels of the per-patch quadtree built once (0 .. 6); 4 suits bicubic patches.
  int treeDepth = 4;
  /// Cells one query may bound before it stops unconverged (>= 1).
  std::size_t maxCells = 1'000'000;
  /// Cut long thin patches into pieces (the contract's Pieces); false searches every patch
  /// whole, as before the pieces (slower on such patches; for comparison).
  bool cutLongPatches = true;
};

/// The closest point of the surface to a query point, with the proven bracket of the distance.
struct ClosestPoint {
  /// |point - query|: an upper bound on the true distance (infinity if no point was seen
  /// below an early-exit cutoff).
  double distance = std::numeric_limits<double>::infinity();
  /// Proven: the true distance is >= lowerBound.
  double lowerBound = 0.0;
  std::size_t patch = 0;  ///< the patch of `point`
  double u = 0.0;         ///< its parameters, in [0, 1]
  double v = 0.0;
  Vec3 point;  ///< r(u, v) (up to rounding)
  /// distance - lowerBound <= tolerance, or lowerBound >= the cutoff given.
  bool converged = false;
  std::size_t cells = 0;  ///< cells whose bounds were computed
};

/// The verdict of a segment clearance test (SurfaceDistance::segmentClearance).
enum class Clearance {
  proven,     ///< every point of the segment is at least the clearance from the surface
  violated,   ///< a surface point lies nearer than the clearance to the segment (`point`)
  undecided,  ///< neither within the cell budget (or at kMaxCellDepth)
};

/// Whether a straight segment keeps a clearance from the surface: the ball of radius R
/// swept along it cuts no deeper than R - clearance.
/// Method: branch and bound over sub-patch cells as for a point, with two lower bounds of
/// the distance between a cell and the segment (convex hull property): the gap between the
/// cell's box and the segment's box, and a separating plane whose normal w points from the
/// segment's point nearest the cell (the mean of its corners) to that cell: min_i c_i . w -
/// max(a . w, b . w). Both are lowered by the rounding allowance of the point query. A cell
/// whose bound reaches the clearance is dropped; its corners are surface points,
/// and one nearer than the clearance to the segment refutes it at once. Near a contact the
/// plane bound lags by the net's thickness, O(h^2), plus the segment's bow against the
/// surface, so a segment whose true clearance exceeds the asked one by d is proven once the
/// cells are about sqrt(d / curvature) small (with a segment no longer than that).
/// Cost: tens of cells for a short segment beside the surface; at most maxCells.
struct SegmentClearance {
  Clearance verdict = Clearance::undecided;
  /// The surface point nearest to the segment among those seen (infinity if none), with its
  /// patch and parameters: for `violated`, a point nearer than the clearance.
  double distance = std::numeric_limits<double>::infinity();
  std::size_t patch = 0;
  double u = 0.0;
  double v = 0.0;
  Vec3 point;
  std::size_t cells = 0;  ///< cells bounded
};

/// Distance queries against one surface: the per-patch quadtrees are built once (see the
/// contract), so prefer this to distanceToSurface for many queries. Holds a copy of the
/// surface.
class SurfaceDistance {
 public:
  /// Throws scallop::Error for a surface without patches, a malformed patch, non-finite
  /// control points or invalid options.
  explicit SurfaceDistance(const Surface& surface, const DistanceOptions& options = {});

  /// The closest point to p (finite, else scallop::Error).
  ClosestPoint closest(Vec3 p) const;
  /// The same, giving up on everything at distance >= cutoff (early exit, see the contract).
  ClosestPoint closest(Vec3 p, double cutoff) const;

  /// Whether every point of the segment [a, b] (finite) is at least `clearance` from the
  /// surface (see SegmentClearance). Throws scallop::Error for non-finite input.
  SegmentClearance segmentClearance(Vec3 a, Vec3 b, double clearance,
                                    std::size_t maxCells = 100'000) const;

  /// The absolute tolerance in use (the default resolved).
  double tolerance() const { return tolerance_; }
  const Surface& surface() const { return surface_; }

  // Out of line: detail::PatchTree is complete only in gouge.cpp.
  ~SurfaceDistance();
  SurfaceDistance(const SurfaceDistance&);
  SurfaceDistance(SurfaceDistance&&) noexcept;
  SurfaceDistance& operator=(const SurfaceDistance&);
  SurfaceDistance& operator=(SurfaceDistance&&) noexcept;

 private:
  Surface surface_;
  DistanceOptions options_;
  double tolerance_ = 0.0;
  double scale_ = 0.0;  // surfaceScale(surface_)
  std::vector<detail::PatchTree> trees_;  // one per patch
  std::vector<detail::PatchNode> nodes_;  // the patches' boxes in a hierarchy; nodes_[0] the root
  std::vector<std::uint32_t> nodePatches_;  // the patches of the leaves, leaf by leaf
  // Tells this engine's cells apart in the per-thread store of halved cells (gouge.cpp);
  // unique per construction, kept by copies (their trees are the same).
  std::uint64_t id_ = 0;
};

/// The distance from p to the surface (builds a SurfaceDistance for this one query).
double distanceToSurface(const Surface& surface, Vec3 p, const DistanceOptions& options = {});
/// The closest point of the surface to p (builds a SurfaceDistance for this one query).
ClosestPoint closestPointOnSurface(const Surface& surface, Vec3 p,
                                   const DistanceOptions& options = {});

struct GougeOptions {
  /// Samples with depth > depthThreshold are counted (surface units; may be negative).
  double depthThreshold = 0.0;
  /// Refuse paths that would take more samples than this (>= 1).
  std::size_t maxSamples = 10'000'000;
  DistanceOptions distance;  ///< for the surface distance queries
  /// Threads sampling blocks at once; 0: every core. The report is the same for any number.
  std::size_t threads = 0;
};

/// Samples per block of the gouge check's threads (see the contract).
inline constexpr std::size_t kGougeSamplesPerBlock = 4096;

/// Where the deepest sample lies.
struct GougeLocation {
  std::size_t pass = 0;  ///< index into ToolPath::passes
  /// Index into that pass's moves; 0 with onLink for the link into the pass.
  std::size_t move = 0;
  bool onLink = false;   ///< on the straight link from the previous pass's end to its start
  Vec3 center;           ///< the ball's centre
  ClosestPoint contact;  ///< the closest point of the surface to `center`
};

struct GougeReport {
  /// max over samples of R - dist(centre, surface); -infinity when there are no samples.
  double signedMaxDepth = -std::numeric_limits<double>::infinity();
  double maxDepth = 0.0;  ///< max(0, signedMaxDepth): how deep the ball cuts in
  /// Proven: no centre of the path, sampled or not, cuts deeper (<= signedMaxDepth +
  /// tolerance + maxSampleGap / 2; see the contract).
  double depthBound = -std::numeric_limits<double>::infinity();
  GougeLocation deepest;  ///< where signedMaxDepth is attained (meaningless without samples)
  std::size_t samples = 0;
  double depthThreshold = 0.0;
  std::size_t samplesDeeperThanThreshold = 0;
  double maxSampleGap = 0.0;  ///< the largest step of path length between samples (<= s)
  double tolerance = 0.0;     ///< of the distance queries
  std::size_t passStartsBelowSurface = 0;  ///< retracted passes starting inside the material
};

/// The interference of the ball with the surface along `path` (see the contract).
GougeReport gougeCheck(const Surface& surface, const ToolPath& path, double sampleSpacing,
                       const GougeOptions& options = {});
/// The same with a prebuilt distance engine (options.distance is then ignored).
GougeReport gougeCheck(const SurfaceDistance& distance, const ToolPath& path, double sampleSpacing,
                       const GougeOptions& options = {});

}  // namespace scallop
