#pragma once
// G-code for a 3-axis mill from a ToolPath: RS-274/NGC as LinuxCNC reads it, or the subset
// grbl 1.1 accepts; and the circumscribed polygon of an arc (arcPolyline), for the
// strategies' arcs that lie in no principal plane.
//
// Contract of gcodeProgram
// ------------------------
// Input:  a ToolPath (toolpath.hpp) as its contract states: finite coordinates, arcs in a
//         principal plane whose two ends lie at the same distance from the centre and share
//         the centre's coordinate normal to the plane (within 10 quanta, below), start != end;
//         toolRadius finite and >= 0; |every coordinate| < kGcodeMaxCoordinate. Options as
//         documented on GcodeOptions. A violation throws scallop::Error naming the option and
//         its value, or the pass and move index (0-based) and the offending value.
// Output: the program text, one block per line ('\n'), deterministic (the same input gives
//         byte-identical text). The tool path holds ball CENTRES; the program drives the
//         ball's TIP = centre - (0, 0, R), R = path.toolRadius, which is what a controller
//         with the tool length offset measured to the tip moves (the header says so).
//         Positions, feeds and tolerances are in the path's units: G20 (inch) or G21 (mm).
//         Time and memory O(number of moves). Polls the thread's job control
//         (job_control.hpp) every 1024 moves: scallop::Cancelled.
// Numbers: fixed point, never an exponent, never nan/inf, never "-0": coordinates with
//         kGcodeDecimalsInch = 5 decimals in inch (quantum q = 0.00001 in = 0.25 um) and
//         kGcodeDecimalsMm = 4 in mm (q = 0.0001 mm); feeds and spindle speed rounded to the
//         same quantum with trailing zeros dropped (F40, F12.5). Every coordinate is rounded
//         to the nearest multiple of q, the arc centre too (I J K = rounded centre - rounded
//         start, exactly), so each printed point is within q/2 per axis of the true one.
//         Rounding changes an arc's two radii by at most sqrt(2) q each: with the 10 q the
//         path may carry, the printed radii differ by < 13 q = 0.00013 in / 0.0013 mm, far
//         inside LinuxCNC's limit (error only above 0.0028 in / 0.028 mm and 0.1 % of the
//         radius; interp_internal.hh CENTER_ARC_RADIUS_TOLERANCE_*) and grbl's (0.005 mm).
// Program: a header of comments (title, units, tool radius, "positions are the ball tip"),
//         then G20|G21; G90 G94 G17 G40 G80 (absolute, feed per minute, xy plane, no cutter
//         compensation, no canned cycle); G91.1 (I J K relative to the arc start); LinuxCNC
//         only: G61 (exact path) or G64 P<blendTolerance>; S<rpm> M3 when spindleRpm > 0;
//         G0 Z<safe>. Then per pass: with a retract (always for the first pass) G0 Z<top>
//         unless there already, top = the safe height, or h - R for a local retract {h, d}
//         (toolpath.hpp; not on the first pass, which comes from the safe height), G0 X Y of
//         the start, for a local retract G0 Z<start + d> (rapid down to d above the start;
//         on later passes no higher than h - R),
//         then G1 Z<start> at plungeFeedRate (straight down); without a retract, G1 straight
//         to the start at feedRate. A local retract must rise (h - R >= the previous pass's
//         last tip z), keep 0 <= d <= h - start z + q (q for rounding in transformed
//         paths), and stay below the safe height (h - R
//         counts as a tip below); else scallop::Error naming the pass. A local retract on
//         a later pass without retractBefore is an error too. The feed is set by a line
//         F<rate> of its own before a feed move whose rate differs from the last one set.
//         Each move, at feedRate: G1 with the axes whose printed value changes;
//         an arc: G17|G18|G19 on a line of its own when the plane changes, then G2 (the
//         ToolMove's `clockwise`, as seen from the positive normal axis, which is RS-274's
//         G2 in every plane: G18's G2 turns clockwise seen from +y) or G3 with both in-plane
//         end coordinates, the normal coordinate if its printed value changes, and both
//         in-plane centre offsets (G17: I J, G18: I K, G19: J K). Finally G0 Z<safe>, M5
//         (when the spindle was started), M2. No line numbers, O-words or '%'; every line is
//         shorter than 80 characters (grbl's line buffer; the title is cut to fit).
// grbl:   the same program without the G61/G64 line (grbl has neither; it rounds corners by
//         its junction deviation setting $11, said in a comment). grbl 1.1 accepts every word
//         written here (G0-3, G17-19, G20/21, G40, G80, G90, G91.1, G94, M2, M3, M5, F, S,
//         X Y Z I J K); it keeps positions as 32-bit floats (about 7 significant digits).
// Degenerate moves: a line or link whose printed end equals the current printed position is
//         left out. An arc whose radius is below kGcodeMinArcRadius (inch: 0.0001, mm:
//         0.00254; LinuxCNC rejects arcs of radius < 0.00005 in / 0.00127 mm after rounding
//         as "zero-radius") is written as its arcPolyline with tolerance q. An arc of at
//         most a half turn whose sagitta r (1 - cos(sweep / 2)) is <= q / 2 is written as a
//         G1 to its end: the two differ by no more than the rounding. Rounding must not
//         change what the controller reads as the arc's sweep: it takes start == end as a
//         full circle, and an end rounded past the start as the long way round. So an arc
//         whose rounded ends coincide, or whose sweep as read back from the rounded numbers
//         differs from the true one by more than 0.5 rad, is written as a G1 line when its
//         sweep is < pi (its chord is then a few q long, its sagitta smaller still), or else
//         as two arcs split at its midpoint (each half a turn, far from both hazards).

#include <limits>
#include <string>
#include <vector>

#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// Decimals of a printed coordinate: 5 in inch, 4 in mm (the quantum q = 10^-decimals).
inline constexpr int kGcodeDecimalsInch = 5;
inline constexpr int kGcodeDecimalsMm = 4;
/// Every coordinate (path, safe height) and rate must be smaller than this in magnitude, in
/// path units: it keeps each block shorter than 80 characters.
inline constexpr double kGcodeMaxCoordinate = 1e5;
/// Arcs of smaller radius are written as polylines (see the contract above).
inline constexpr double kGcodeMinArcRadiusInch = 1e-4;
inline constexpr double kGcodeMinArcRadiusMm = 2.54e-3;

enum class GcodeDialect {
  linuxcnc,  ///< RS-274/NGC as LinuxCNC 2.9 reads it (checked with its rs274 interpreter)
  grbl,      ///< the subset grbl 1.1 accepts: no G61/G64
};

/// Options of gcodeProgram. Lengths in the path's units. The four NaN-initialised values
/// must be set: there is no default that suits both inch and mm, or every machine.
struct GcodeOptions {
  GcodeDialect dialect = GcodeDialect::linuxcnc;
  /// z of the tool TIP for rapid moves between passes; must be above every tip z the path
  /// reaches, the top of G18/G19 arcs included, and below kGcodeMaxCoordinate.
  double safeHeight = std::numeric_limits<double>::quiet_NaN();
  /// Cutting feed, units per minute: finite, >= q and < kGcodeMaxCoordinate.
  double feedRate = std::numeric_limits<double>::quiet_NaN();
  /// Feed of the plunge from the safe height down to a pass start after a retract, units
  /// per minute; same range as feedRate.
  double plungeFeedRate = std::numeric_limits<double>::quiet_NaN();
  /// Spindle speed, revolutions per minute, clockwise (M3): 0 writes no spindle words (the
  /// spindle is controlled by hand), otherwise in [1, kGcodeMaxCoordinate).
  double spindleRpm = std::numeric_limits<double>::quiet_NaN();
  /// LinuxCNC only: 0 writes G61 (exact path: corners are not rounded); > 0 writes
  /// G64 P<blendTolerance> (the controller may leave the programmed path by up to this much,
  /// rounding corners and merging nearly collinear segments, to keep the feed up). 0 or in
  /// [q, kGcodeMaxCoordinate). Ignored for grbl.
  double blendTolerance = 0.0;
  /// Put in the first comment. Parentheses become brackets, control characters spaces and
  /// non-ASCII bytes '?', and it is cut to keep the line under 80 characters.
  std::string title;
};

/// The G-code program that cuts `path` (see the contract above). Throws scallop::Error on
/// invalid options or an invalid path.
std::string gcodeProgram(const ToolPath& path, const GcodeOptions& options);

/// What the program gcodeProgram(path, options) writes costs in motion: the length of each
/// kind of move (path units, of the true tips, before rounding) and the time at the rates.
///   feed:   every pass's moves (arcs as arcs: r x sweep, with the change along the plane's
///           normal as a helix) and the G1 links between passes, at options.feedRate;
///   plunge: the G1 straight down into each retracted pass's start, at plungeFeedRate;
///   rapid:  every G0: the rises (to the safe height or a local retract's height), the
///           traverses between passes, the rapid descents of local retracts, and the final
///           rise to the safe height; not the first traverse (from wherever the machine
///           was) nor the program's first G0 Z<safe>, at rapidRate.
/// Minutes = length / rate for each kind: no acceleration, and each G0 taken at rapidRate
/// along its straight line (a machine moves G0 at its axes' limits: set rapidRate to what
/// its slowest axis reaches). Validation as gcodeProgram's, and rapidRate as the feeds.
struct GcodeMotion {
  double feedLength = 0.0;
  double plungeLength = 0.0;
  double rapidLength = 0.0;
  double feedMinutes = 0.0;
  double plungeMinutes = 0.0;
  double rapidMinutes = 0.0;
  double minutes = 0.0;  ///< the estimated cycle time: the sum of the three
};
GcodeMotion gcodeMotion(const ToolPath& path, const GcodeOptions& options, double rapidRate);

/// The polygon circumscribing an arc, for arcs in any plane: the arc runs counter-clockwise
/// about the unit vector `axis` (right-hand rule) from `start` to `end` around `center`, of
/// radius r = |start - center|, sweep in (0, 2 pi] (end == start: the full circle).
/// Returns vertices v_0 = start, v_1 .. v_m, v_{m+1} = end (bit for bit), where every edge
/// lies on a tangent line of the circle, so the polyline never passes inside the circle,
/// and its largest distance from the arc is r (1 / cos(d / 2) - 1) <= tolerance, with the
/// fewest segments that allow it.
/// Construction: m + 1 tangent lines at the angles t_k = k d, k = 0..m, d = sweep / m; the
/// first touches at start, the last at end. Consecutive tangents at t_{k-1} and t_k meet at
/// angle (t_{k-1} + t_k) / 2, distance r / cos(d / 2) from the centre (the right triangle
/// centre - touching point - meeting point has its angle d / 2 at the centre): these are
/// v_1 .. v_m, the first and last segments each covering half a step d / 2, the others d.
/// Their distance to the circle, r (sec(d / 2) - 1), is the polyline's largest; so
/// m = ceil(sweep / d_max), d_max = 2 acos(r / (r + tolerance)) < pi.
/// Preconditions (scallop::Error otherwise): finite input; |axis| = 1 within 1e-9;
/// r > 0; start - center and end - center orthogonal to the axis, and |end - center| = r,
/// within `tolerance`; tolerance > 0; at most kArcPolylineMaxSegments segments needed.
/// (The ends are kept as given: an end off the plane or the circle by e moves the last
/// segment by up to e, which may then dip inside the circle by up to e.)
/// Time and memory O(m).
std::vector<Vec3> arcPolyline(Vec3 start, Vec3 end, Vec3 center, Vec3 axis, double tolerance);

/// Upper bound on the number of segments arcPolyline returns (about tolerance / r > 5e-12
/// for a full circle).
inline constexpr int kArcPolylineMaxSegments = 1'000'000;

}  // namespace scallop
