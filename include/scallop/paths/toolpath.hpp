#pragma once
// The tool path in space: what the contour and raster strategies produce and what the
// G-code writer, the JSON report and the figures consume.
//
// Contract
// --------
// Positions are the centre of the ball-end cutter, in the surface's units (inches or
// millimetres), in the machine frame of a 3-axis mill: z up, the tool above the material.
// (The G-code writer turns centres into the ball's tip, centre - R z, which is what a
// controller with the tool length measured to the tip drives.)
// A ToolPath is a sequence of passes in machining order. A pass is one uninterrupted cutting
// move: it starts at `start` and each move runs from where the previous one ended to its
// `end`. Between passes the tool either retracts (ToolPass::retractBefore == true) or feeds
// straight from the previous pass's end to this pass's start at the cutting feed (false:
// the strategy or the linker, linking.hpp, has proven that this link cannot gouge).
// A retract is one of two kinds:
//   - to the safe height (ToolPass::retract absent; what the strategies make): rapid up to
//     the G-code's safe height, across, and down at the plunge feed the whole way;
//   - local (ToolPass::retract = {height h, plunge d}; made by the linker, which proves it
//     clear): rapid straight up from the previous pass's end to centre height h, across at
//     h, rapid straight down to start.z + d, and down the last d at the plunge feed.
//     Invariants: h >= the previous pass's end z, 0 <= d <= h - start.z (the G-code
//     writer allows one printed quantum more, for rounding in scaled paths). On
//     the first pass (no previous end) the tool comes from the safe height and only d is
//     used: rapid down to start.z + d, the rest at the plunge feed.
// Arcs lie in a principal plane (the G-code planes G17 xy, G18 zx, G19 yz): `center` and
// the two ends share the coordinate normal to the plane, and both ends lie at the same
// distance from the centre (within rounding). `clockwise` is as seen from the positive end
// of the axis normal to the plane, looking towards the origin: RS-274's G2. A quarter turn
// or more is allowed, a full circle is not (start != end).

#include <cstddef>
#include <optional>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

enum class ArcPlane {
  xy,  ///< G17: normal +z
  zx,  ///< G18: normal +y
  yz,  ///< G19: normal +x
};

enum class MoveKind { line, arc };

struct ToolMove {
  MoveKind kind = MoveKind::line;
  Vec3 end;                       ///< where the move ends (tool centre)
  Vec3 center;                    ///< arc only
  ArcPlane plane = ArcPlane::xy;  ///< arc only
  bool clockwise = true;          ///< arc only: G2 when true, G3 when false
};

/// Coordinates (e1, e2, n) of a point in an arc plane's frame, right-handed, so that
/// counter-clockwise seen from the normal's positive end is increasing atan2(e2, e1):
/// G17 (x, y, z), G18 (z, x, y), G19 (y, z, x). fromArcPlane is the inverse.
constexpr Vec3 toArcPlane(ArcPlane plane, Vec3 a) {
  switch (plane) {
    case ArcPlane::xy:
      return {a.x, a.y, a.z};
    case ArcPlane::zx:
      return {a.z, a.x, a.y};
    case ArcPlane::yz:
      return {a.y, a.z, a.x};
  }
  return a;
}
// Each arc plane's coordinates are a cyclic shift of (x, y, z), whose inverse is the same
// shift applied twice.
constexpr Vec3 fromArcPlane(ArcPlane plane, Vec3 a) { return toArcPlane(plane, toArcPlane(plane, a)); }

/// A retract that rises only as far as needed (see the contract above); ball centres.
struct LocalRetract {
  double height = 0.0;  ///< h: centre z of the traverse
  double plunge = 0.0;  ///< d: the last part of the descent, made at the plunge feed
};

/// An arc move from `start` in its plane's frame (toArcPlane): the centre, the radius (the mean
/// of the two ends' distances from the centre), the start's angle, the signed sweep in
/// radians (counter-clockwise seen from the normal's positive end positive: in (0, 2 pi] for
/// G3, [-2 pi, 0) for G2; start == end is a full turn), and the start's and end's coordinate
/// along the normal (equal but for rounding; a helix in between).
struct ArcGeometry {
  ArcPlane plane = ArcPlane::xy;
  Vec3 center;
  double radius = 0.0;
  double startAngle = 0.0;
  double sweep = 0.0;
  double startLevel = 0.0;
  double endLevel = 0.0;
};
ArcGeometry arcGeometry(Vec3 start, const ToolMove& arc);
/// The arc's point at the fraction t in [0, 1] of its sweep.
Vec3 pointOnArc(const ArcGeometry& arc, double t);
/// The length of a move from `start`: a line's chord, an arc's r |sweep| (with the rise along
/// the normal of a helix).
double moveLength(Vec3 start, const ToolMove& move);

struct ToolPass {
  Vec3 start;                   ///< tool centre where the pass begins
  std::vector<ToolMove> moves;  ///< each from the previous end (or `start`) to its `end`
  bool retractBefore = true;    ///< retract before this pass, else feed straight (see above)
  /// With retractBefore: a local retract; absent: via the safe height (see above).
  std::optional<LocalRetract> retract = std::nullopt;
};

/// Where the pass ends: its last move's end, or its start when it has no move.
Vec3 passEnd(const ToolPass& pass);
/// The same path run backwards: moves in reverse order, each ending where its predecessor
/// began, arcs turning the other way (about the same centre, in the same plane).
ToolPass reversedPass(const ToolPass& pass);

struct ToolPath {
  Units units = Units::inch;
  double toolRadius = 0.0;        ///< R of the ball-end cutter, in `units`
  std::vector<ToolPass> passes;   ///< in machining order
};

}  // namespace scallop
