#pragma once
// Linking: the moves between the passes of a finished tool path (either strategy), so that
// the tool does not climb to the safe height and plunge at feed before every pass. Passes
// are put in an order that makes short links common, and each link is the cheapest kind
// that is PROVEN not to gouge: a direct feed at cutting height, or a local retract over the
// stock near the link; only when neither is proven, the safe-height retract the strategies
// make.
//
// Contract
// --------
// Input:  a valid surface (surface.hpp; cut from above, z up) and a ToolPath over it
//         (toolpath.hpp: ball centres, R = toolRadius > 0, the surface's units, finite
//         positions) as a strategy made it; options (LinkOptions). The material is taken to
//         be the design surface, as gouge.hpp takes it: a finishing path, whose stock left
//         by roughing and whose scallops must stay below the clearance margin.
// Units:  passes that the strategy linked itself (retractBefore == false: raster's
//         zigzag links between planes) stay glued to their predecessor: a unit is a run of
//         passes whose head is retracted and whose others are not. Units are reordered;
//         the passes inside a unit, and their own links, are left exactly as they are.
// Order:  (reorder == true) the first unit stays first; then, greedily, the unit whose
//         entry is nearest (3D distance) to the current end comes next, ties to the lower
//         index. Entries of a unit: its start; with PassDirection::zigzag also the end of a
//         single-pass unit (the pass is then run backwards: moves in reverse order, arcs'
//         `clockwise` flipped, so climb and conventional milling alternate as in raster's
//         zigzag); and every vertex of a single closed pass (end == start bit for bit), which
//         is then rotated to start there (the same loop in the same direction).
//         PassDirection::keep never reverses: every pass keeps the strategy's direction, so
//         the cutting side (climb or conventional) is the strategy's throughout.
//         Never drops or duplicates a pass (LinkedPath::origin is a permutation).
// Links:  for every unit's head after the first, with E the previous pass's end and S its
//         start (ball centres), depth(c) = R - dist(c, surface), and the allowance at an end
//         a(E) = max(depth(E), 0) + epsilon (depth from the distance's upper bound: never
//         above the true depth), epsilon = gougeAllowance:
//         1. direct (retractBefore = false, a G1 at the cutting feed) when |S - E| <=
//            directLinkMax and every centre of the segment [E, S] is proven at distance
//            >= R - max(a(E), a(S)) from the surface: the ball cuts no deeper along the link
//            than at its ends plus epsilon (so not at all where the ends touch, up to epsilon);
//         2. local retract {h, d} otherwise: Z = a proven upper bound of the surface's height
//            within horizontal distance R of the segment E.xy - S.xy (branch and bound on
//            sub-patches, raster.cpp's link height), h = max(E.z, S.z, Z + R + clearance).
//            Proof: at height >= Z + R over that segment every centre is at least R from
//            every surface point (those within R horizontally lie below Z, the others are
//            farther than R horizontally): the traverse and the vertical moves above Z + R
//            are clear. The vertical moves below Z + R, E up and S down, are proven by sphere
//            tracing to keep depth <= a(E) (resp. a(S)). d = min(plunge, h - S.z);
//         1b. else, when |S - E| <= directLinkMax, the feed over the drop envelope: [E, S]
//            lifted by liftToDropEnvelope (envelope.hpp, eps = epsilon, every move proven to
//            cut no deeper than epsilon) when that leaves both ends where they are; its
//            moves go in front of the pass (LinkedPath::linkMoves), which then starts at E
//            (retractBefore = false). Why: two ends beside an edge or on a crest touch the
//            surface, and the straight feed between them dips into it where the envelope
//            sags (contour passes that run on past the edges: 0 of 83 straight feeds proven
//            on paper-1, 82 over the envelope);
//         3. when the vertical moves of 2 are not proven (the surface overhangs an end), the
//            direct feed of 1 again with a larger budget of steps (1 gives up after 256 steps,
//            where the proof creeps along a move that slides on the surface; here 4,000);
//         4. else the safe-height retract (retract absent), counted in unprovenLinks.
//         The first pass gets {h, d} with h = S.z + d (the G-code then rapids down from the
//         safe height to d above S) when its descent is proven as in 2, else nothing.
//         Proof tool: sphere tracing (clearance.hpp's segmentClears, raster's pass-end
//         proof) on gouge.hpp's proven lower bound of the distance, a 1-Lipschitz function:
//         from a centre whose bound exceeds the limit by m, every centre within m is clear.
//         Distance tolerance epsilon / 8. Not proven, not claimed: the final rise from the
//         last pass to the safe height (the G-code writer's, as before).
// Output: LinkedPath: the relinked ToolPath, for each of its passes where it came from, and
//         counts and lengths (LinkStats). The G-code writer turns local retracts into G0
//         rises, traverses and descents and a short G1 plunge (gcode.hpp); its safe height
//         must lie above every h - R (defaultGcodeOptions' 0.2 in / 5 mm above the surface's
//         control points does while clearance + the surface's height bound stay below it).
// Complexity: ordering O(U (U + V)) for U units and V vertices of closed single passes
//         (budget maxOrderingWork: scallop::Error beyond it, naming it). Each link: a
//         height bound (at most kLinkMaxCells sub-patches) and at most four sphere traces
//         of at most 4,256 distance queries each, every query capped at
//         kLinkDistanceMaxCells cells: bounded per pass.
// Errors: scallop::Error for options out of range (naming the option and value), an
//         invalid surface, a path whose units differ from the surface's, a tool radius that
//         is not positive, non-finite positions (naming the pass), or the ordering budget.

#include <cstddef>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"

namespace scallop {

/// Cells one distance query of the link proofs may bound before it gives up (the proof
/// then fails, and the link falls back to a safer kind).
inline constexpr std::size_t kLinkDistanceMaxCells = 20'000;

enum class PassDirection {
  zigzag,  ///< a single pass may run backwards when that shortens its link (climb and
           ///< conventional milling alternate, as in raster's zigzag)
  keep,    ///< every pass runs as the strategy made it: one cutting side throughout
};

/// Options of linkToolPath. Lengths in the surface's units; 0 selects the default given.
struct LinkOptions {
  bool reorder = true;  ///< order the units nearest-next (false: the strategy's order)
  PassDirection direction = PassDirection::zigzag;
  /// Direct feeds are tried for links no longer than this (>= 0); 0: 4 R.
  double directLinkMax = 0.0;
  /// Traverse margin above the proven surface bound (>= 0); 0: 0.02 in / 0.5 mm. Must
  /// exceed the stock left above the surface (scallops, roughing allowance).
  double clearance = 0.0;
  /// The last part of every descent made at the plunge feed (>= 0); 0: 0.02 in / 0.5 mm.
  double plunge = 0.0;
  /// epsilon: how much deeper than at its ends the ball may come along a link (> 0 when
  /// given); 0: 1e-6 x surfaceScale.
  double gougeAllowance = 0.0;
  /// Greedy ordering comparisons allowed (units x (units + loop vertices)).
  double maxOrderingWork = 2e9;
};

struct LinkStats {
  std::size_t passes = 0;
  std::size_t units = 0;           ///< runs of passes the linker may move (see the contract)
  std::size_t reversedPasses = 0;  ///< run backwards
  std::size_t rotatedLoops = 0;    ///< closed passes started at another vertex
  std::size_t directLinks = 0;     ///< feeds at cutting height made by the linker
  std::size_t envelopeLinks = 0;   ///< of which over the drop envelope (several moves)
  std::size_t localRetracts = 0;   ///< retracts over the local stock (first pass excluded)
  std::size_t unprovenLinks = 0;   ///< left as safe-height retracts: no proof found
  std::size_t strategyLinks = 0;   ///< the strategy's own links, left alone
  bool firstPlungeShortened = false;  ///< the first pass's descent proven: rapid to d above
  double directLinkLength = 0.0;   ///< total length of the direct links
  double gougeAllowance = 0.0;     ///< epsilon used
  double clearance = 0.0;          ///< traverse margin used
  double plunge = 0.0;             ///< plunge distance used
  double directLinkMax = 0.0;      ///< longest direct link tried
};

struct LinkedPath {
  ToolPath path;
  /// origin[i]: the index in the input path of output pass i (a permutation).
  std::vector<std::size_t> origin;
  /// reversed[i]: output pass i runs backwards relative to the input.
  std::vector<bool> reversed;
  /// linkMoves[i]: moves the linker put in front of output pass i (a feed over the drop
  /// envelope from the previous pass's end, see the contract); the pass proper starts where
  /// the last of them ends. 0 for every other pass.
  std::vector<std::size_t> linkMoves;
  LinkStats stats;
};

/// The relinked path (see the contract). Throws scallop::Error on invalid input.
LinkedPath linkToolPath(const Surface& surface, const ToolPath& path,
                        const LinkOptions& options = {});

}  // namespace scallop
