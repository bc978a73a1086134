#pragma once
// The drop envelope: a ball-end tool path lifted, where it would cut into the surface, to
// the lowest position of the ball that touches nothing, with a proof.
//
// Why: the raster strategy offsets each section in its own vertical plane (Chou et al.,
// "Scallop hull and its offset": exact within that plane only), so the ball cuts into the
// neighbouring sections wherever the surface rises across the plane; the contour strategy's
// centres r + R n cut in where a concave radius is below R, at creases, and where another
// part of the surface comes within R; and the straight moves between exact centres sag below
// the true offset. A 3-axis machine can only lower the ball from above: the lowest gouge-free
// centre over a point (x, y) is the drop envelope
//     Z(x, y) = max { p_z + sqrt(R^2 - |p_xy - (x, y)|^2) : p on the surface, |p_xy - (x, y)| <= R }
// (the ball and the shank above it clear of the surface).
//
// Contract
// --------
// Input:  a SurfaceDistance (gouge.hpp) of the surface, a tool path (toolpath.hpp: ball
//         centres, radius R > 0, the surface's units), a depth tolerance eps > 0 (default
//         1e-6 of surfaceScale).
// Output: the path with the same passes in the same order, each pass's moves replaced by
//         moves that run through the same (x, y) stations (inserted ones in between), where:
//         - every vertex c of the output lies on or above the input's point it stands for,
//           lifted straight up (x and y unchanged) only as far as needed: it is the input
//           point when the vertical ray above it is proven clear, else the lowest height
//           found (within eps / 4) at which the vertical segment from it up to Ztop = (the
//           surface's highest control point) + R is proven clear: the ball and the shank
//           above it (a 3-axis tool) miss the surface there by R - eps / 2 at least. The
//           true Z(x, y) is at most that height (within eps / 4 above it every centre proven
//           clear), and no lower centre on that vertical is clear by more than eps / 2;
//         - every straight move of the output is proven (gouge.hpp's segmentClearance) to
//           keep every centre along it at least R - eps from the surface: the ball cuts no
//           deeper than eps anywhere along it;
//         - an input arc is kept as it is when both its ends are kept and every chord of a
//           subdivision with sagitta s <= eps / 4 is proven R - eps + s clear (every point of
//           the arc lies within s of its chord); otherwise it becomes straight moves through
//           points of the arc, lifted and refined as lines are;
//         - with a sag tolerance s > 0, a proven straight move longer than sqrt(8 R s)
//           horizontally whose midpoint lies more than s above the envelope is split there
//           (the midpoint lowered onto the envelope), so that no cutting move leaves more
//           than about s of material where the envelope sags between its ends; only the
//           input moves EnvelopeOptions::sagMoves names (every move by default: a strategy
//           names its cutting moves, so that its links keep their height);
//         - a move not proven is halved, its midpoint lifted as a vertex, and each half tried
//           again, at most kEnvelopeMaxHalvings times, then kept with its depth unproven
//           (counted in EnvelopeReport::unprovenMoves; none on the paper's surfaces or the
//           tests' cases). Shank clearance is proven at vertices; between them only the ball's.
// Proof of each step: segmentClearance's lower bounds (convex hull property, rounding
//         allowance included); the heights come from a local maximisation of
//         p_z + sqrt(R^2 - d^2) over the patch (Newton's method, a lower bound of Z: a real
//         contact) confirmed by the proof, or from bisection on the monotone "vertical
//         segment clear" when that fails.
// Report: vertices lifted (by more than eps), the largest lift, lifted stretches (runs of
//         moves whose vertices were lifted by more than a threshold: where, how long), moves
//         in and out, arcs kept and replaced, proofs run, unproven moves.
// Errors: scallop::Error for eps not positive and finite, a path whose units or radius do
//         not match, non-finite positions, or more than maxMoves output moves (a tolerance
//         too fine for the path: the message says so).
// Threads: the passes are lifted in parallel (EnvelopeOptions::threads), each with its own
//         state; a pass's first and last vertices are lifted without the state carried along
//         the pass, so a pass fed from the previous one's end starts exactly where that end
//         was lifted to. The output is the same for any number of threads.
// Complexity: a proof costs tens of cells near the surface; a lifted vertex a Newton solve
//         and one proof (a bisection of ~log2(height / eps) proofs where the local
//         maximum is not the global one). Moves come out about sqrt(8 eps rho) long on a
//         curved stretch of lifted path (rho the path's radius of curvature).

#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "scallop/paths/gouge.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// Halvings of one input move before its remaining pieces are kept unproven.
constexpr int kEnvelopeMaxHalvings = 40;

struct EnvelopeOptions {
  /// eps: the deepest cut allowed (surface units, > 0); 0 selects 1e-6 of surfaceScale.
  double depthTolerance = 0.0;
  /// A lifted stretch is reported where vertices are lifted by more than this (>= 0); 0
  /// selects 10 eps.
  double stretchThreshold = 0.0;
  /// Budget: output moves in all (>= 1).
  std::size_t maxMoves = 5'000'000;
  /// Budget: cells per clearance proof (>= 1).
  std::size_t maxCellsPerProof = 100'000;
  /// Threads lifting passes at once; 0: every core. The result is the same for any number.
  std::size_t threads = 0;
  /// > 0: a straight move longer than sqrt(8 R sagTolerance) horizontally whose midpoint lies
  /// more than this above the envelope there (its drop-cutter height) is split there, the
  /// midpoint lowered onto the envelope, and each half tried again (within
  /// kEnvelopeMaxHalvings): where the envelope sags between two lifted vertices (a valley
  /// across the pass) a straight move would leave that much material. 0: moves are only
  /// split when not clear.
  double sagTolerance = 0.0;
  /// Per pass, the input moves [first, last) the sag rule applies to (a pass beyond the end
  /// of the list: all its moves): the cutting moves, not the links, which stand above the
  /// surface by design and must keep their height.
  std::vector<std::pair<std::size_t, std::size_t>> sagMoves;
};

/// A run of consecutive output vertices of one pass lifted by more than the threshold: an
/// area the tool as given cannot reach (a smaller ball could).
struct LiftedStretch {
  std::size_t pass = 0;
  Vec3 from;             ///< its first lifted vertex (tool centre, after lifting)
  Vec3 to;               ///< its last
  double length = 0.0;   ///< path length between them
  double maxLift = 0.0;  ///< the largest lift of its vertices
};

struct EnvelopeReport {
  double depthTolerance = 0.0;     ///< eps used
  double stretchThreshold = 0.0;   ///< used
  std::size_t movesIn = 0;
  std::size_t movesOut = 0;
  std::size_t arcsKept = 0;
  std::size_t arcsReplaced = 0;
  std::size_t verticesLifted = 0;  ///< lifted by more than eps
  double maxLift = 0.0;            ///< the largest lift of any vertex
  double liftedLength = 0.0;       ///< total length of the lifted stretches
  std::vector<LiftedStretch> stretches;
  std::size_t proofs = 0;          ///< clearance proofs run
  std::size_t unprovenMoves = 0;   ///< moves kept without a proof (see the contract)
};

/// The path lifted to the drop envelope (see the contract). `moveMap`, if given, receives
/// for each pass and each input move the number of output moves of that pass up to and
/// including the ones it became (so a strategy can map its bookkeeping of moves).
ToolPath liftToDropEnvelope(const SurfaceDistance& distance, const ToolPath& path,
                            const EnvelopeOptions& options, EnvelopeReport& report,
                            std::vector<std::vector<std::size_t>>* moveMap = nullptr);

/// The height above which a ball centre of radius R is clear of the whole surface: R (and a
/// relative hair for rounding) above its highest control point (convex hull property).
double ballTop(const Surface& surface, double radius);
/// The same above any geometry whose highest point is `highest` (a mesh's highest vertex).
double ballTopAbove(double highest, double radius);

/// Drop-cutter heights: the drop envelope Z(x, y) at points one after another, each lifted
/// from below the whole surface as liftToDropEnvelope lifts a vertex (the lowest height found
/// within eps / 4 from which the vertical segment up to Ztop is proven R - eps / 2 clear;
/// -infinity where no surface point lies within R of the vertical line). The last contact
/// seeds the next point's Newton solve: neighbouring points cost about one proof each. Not
/// thread-safe (one per thread). Errors: R not positive and finite, a depth tolerance
/// negative or not finite, eps >= R.
class DropCutter {
 public:
  DropCutter(const SurfaceDistance& distance, double radius, const EnvelopeOptions& options = {});
  ~DropCutter();
  DropCutter(const DropCutter&) = delete;
  DropCutter& operator=(const DropCutter&) = delete;
  double height(double x, double y);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Running a pass on past one of its ends, over the surface's edge.
///
/// Contract
/// --------
/// Why:    a pass that stops where its plane leaves the surface (or R beyond, as the scallop
///         hull ends) leaves the surface along an edge uncut where the edge crosses the planes
///         obliquely and the surface slopes down to it: the ball finishes a point q near the
///         edge only from its centre q + R n(q), R |n_xy(q)| beyond the edge, which the plane
///         through that centre reaches up to R |n_xy| / sin(angle between edge and plane)
///         further on than where it left the surface; and the edge line itself between two
///         passes is touched only by balls beside it.
/// Input:  the pass's end centre `end`, a direction whose horizontal part is not zero (the
///         pass's, onwards; none: nothing to run on), R > 0, the pass's band (below), a step
///         > 0 and a length >= 0.
/// Band:   which surface points the pass is responsible for, by the plane coordinate of the
///         centre that finishes them: W(q) = normal . (q + offset n(q)), n the upward unit
///         normal; offset 0 for contour (the contacts lie in the planes, normal . q = w),
///         R for raster (the centres lie in the planes, e . c = w). The band is [lo, hi],
///         half way to the neighbouring planes, unbounded beyond the outermost ones.
/// Output: the vertices c_k = end_xy + k step h (h the horizontal unit direction), k = 1, 2,
///         ..., each at the height where it stands on the drop envelope: lifted from below the
///         whole surface exactly as liftToDropEnvelope lifts a vertex (the lowest height found
///         within eps / 4 from which the vertical segment up to Ztop is proven R - eps / 2
///         clear). The run goes on to the last c_k within `length` before the first one
///         that has no surface point within R of its vertical line (proven: it stands at
///         the bottom), and is then cut back to its last vertex that touches the surface
///         inside the band (W(q) of its closest surface point q, within the distance's
///         tolerance, in [lo, hi]); vertices between that touch a neighbour's points stay
///         (beyond an edge a ball grazes the edge's points, a neighbour's, before it reaches
///         the offsets of its own).
///         The moves between them are not proven here (liftToDropEnvelope proves them).
/// Cost:   per vertex one lift (a Newton solve and a proof or two) and one closest point.
struct RunOnBand {
  Vec3 normal;          ///< unit
  double offset = 0.0;  ///< 0 (contour) or R (raster), see the contract
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
};

/// How far past its ends (in R) the strategies let a pass run on: an edge sloping down at 35
/// degrees and crossing the planes at 15 needs 2.2 R.
inline constexpr double kRunOnLength = 4.0;

std::vector<Vec3> runOnPastEnd(const SurfaceDistance& distance, Vec3 end, Vec3 direction,
                               double radius, const RunOnBand& band, double step, double length,
                               const EnvelopeOptions& options = {});

/// The step the strategies run on with: half the gap to the nearest plane, within [R/64, R/4].
/// A chord of the envelope (radius of curvature >= R about an edge) then sags by at most
/// gap^2 / (32 R): H sin^2(alpha) / 4 at the flat spacing.
inline double runOnStep(double gap, double radius) { return std::clamp(0.5 * gap, radius / 64.0, radius / 4.0); }

/// Both ends of `pass` run on (runOnPastEnd, at most kRunOnLength R each): from its start
/// along `backward`, from its end along `forward`, as line moves.
void runPassOn(const SurfaceDistance& distance, ToolPass& pass, Vec3 backward, Vec3 forward, double radius,
               const RunOnBand& band, double step);

/// The drop envelope along the horizontal line origin + t h, t in [from, to] (h the unit
/// horizontal direction), in runs. The vertices c_k at t = from + k step, k = 0, 1, ..., are
/// dropped onto the envelope as runOnPastEnd's are; a run is a maximal sequence of
/// consecutive vertices that touch the surface inside the band, kept when it has two or more.
/// What a raster plane that its section does not reach (or barely) contributes: its balls
/// still finish points beside it, shifted across the plane by up to R where the surface
/// slopes across it. Errors as runOnPastEnd's, a vertical direction, more than 10 million
/// steps.
std::vector<std::vector<Vec3>> dropLineRuns(const SurfaceDistance& distance, Vec3 origin,
                                            Vec3 direction, double from, double to, double radius,
                                            const RunOnBand& band, double step,
                                            const EnvelopeOptions& options = {});

}  // namespace scallop
