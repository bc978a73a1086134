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

#include <cstddef>
#include <vector>

#include "scallop/gouge.hpp"
#include "scallop/toolpath.hpp"
#include "scallop/vector.hpp"

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

}  // namespace scallop
