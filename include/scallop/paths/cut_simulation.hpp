#pragma once
// Simulating the cut of a ball-end mill on a height map (z-map) of the stock, and comparing
// the result with the design surface: gouges (material removed below the surface) and the
// scallops left (material above it). `scallop verify` and the tests' judge of every plan.
//
// Contract
// --------
// Input:  a valid Surface (surface.hpp) and the tool's moves as ball CENTRES (SweptMove):
//         from a G-code program (machine_program.hpp, read by gcode_reader.hpp; tip + R z) by sweptMoves(program, R), or
//         from a ToolPath (toolpath.hpp) by sweptMoves(path). Lines (also zero-length and
//         vertical), arcs in the three principal planes (quarter turns, full circles,
//         helices); every coordinate finite. SimulationOptions as documented there.
// Grid:   the points (x0 + i d, y0 + j d), i < columns, j < rows, cover the xy box of the
//         surface's control points (which contains the surface) grown by `margin`. The
//         spacing d is given, or chosen so that a scallop ridge between two grid points is
//         missed by at most H / 4: a ridge line passes within d / 2 of a grid point, and on
//         a flat surface the scallop's flanks rise at slope s = sqrt(2RH - H^2) / (R - H)
//         at a cusp of height H (the ball's slope where it meets its neighbour
//         l / 2 = sqrt(2RH - H^2) off its axis), so d = H / (2 s) keeps s d / 2 <= H / 4
//         (`heightErrorBound` reports s d / 2 for the d used; on a slope of angle theta a
//         ridge across the slope may lie d / (2 cos theta) from a point along the surface, and
//         the bound grows by 1 / cos theta). More than `maxPoints` grid
//         points is an error naming the grid and the budget.
// Stock:  at each grid point p the stock's top z is min(stockTop, the lowest point of every
//         swept ball above p): the z-map. For a line the swept ball is a capsule whose
//         lowest point above p is the minimum over t in [0, 1] of the convex function
//         g(t) = c_z(t) - sqrt(R^2 - |p - c_xy(t)|^2): at its stationary point in closed
//         form (below, sweptBallLowest), clamped to [0, 1]. For a flat arc (constant normal
//         coordinate) in G17 the lowest point is above the arc point nearest to p in xy; in
//         G18/G19 the ball cuts the vertical plane through p parallel to the arc's in a disk
//         of radius k = sqrt(R^2 - e^2) (e the distance between the planes), and g is
//         stationary only where the lowest point lies on the radial line of the arc point
//         (the envelope of the disks: the outer circle of radius r + k below, the inner
//         one of radius r - k above): up to four angles in closed form, plus the two ends.
//         A helix in G17 (z linear in the angle) has its stationary points at the roots of
//         a quadratic in cos(angle) (cut_simulation.cpp derives it): exact too. A helix in
//         G18/G19 (the horizontal normal coordinate changes, as rounding of a printed
//         program may do by a few quanta) is bounded by branch and bound on its angle
//         (lower bound from each piece's box, upper bound from genuine positions) to
//         kHelixTolerance (R + |centre| + r), at most kHelixMaxPieces pieces per point.
//         Every value is g at a genuine position of the ball (never below the true
//         envelope), and the true minimiser is among the candidates: the z-map is exact up
//         to rounding at every grid point (G18/G19 helices: up to their tolerance above),
//         so no false gouge appears.
//         (Ends of passes, links and rapids are moves like the others: a rapid through
//         material cuts it and is counted.)
// Design: at each grid point, the highest point of the surface on the vertical line, what a
//         3-axis mill sees from above, or "no surface" (-infinity) off the footprint: each
//         patch is cut into sub-patches (quadtree) until each covers at most 16 x 16 grid
//         points and the Jacobian d(x, y) / d(u, v) has Bernstein coefficients of one
//         strict sign on it (no fold: one sheet over each point) or it covers at most 4
//         points, to depth 10 (1/1024 of the patch's side). At each grid point in a
//         sub-patch's control box, Newton's method on (x, y)(u, v) = p is run from the
//         sub-patch's centre (on a fold cell, also from four more starts), projected onto the
//         sub-patch, and a solution is accepted when it converges to |(x, y) - p| <= 1e-12
//         scale (scale = surfaceScale); the highest one wins. Converged, not proven: on a
//         fold cell (within 1/1024 of the patch's side of a vertical tangent) a sheet may be
//         missed, and over a vertical wall (the Jacobian zero everywhere, an image of no
//         area) lying along a grid line the value is some point of the wall on the vertical
//         line or the surface below, not necessarily the wall's top; elsewhere the value is
//         exact up to rounding. Time O(P) Newton solves and sub-patches.
// Output: SimulationReport: the two grids, and over the points with surface:
//         gouge = design - stock > 0, measured vertically (max, where, points and area beyond
//         gougeTolerance). A ball that comes within R - delta of the surface (an interference
//         delta, as gouge.hpp measures it) leaves a vertical gouge >= delta above the surface
//         point q nearest its centre c: with rho = |q_xy - c_xy| <= R - delta, the ball's
//         bottom above q_xy is at c_z - sqrt(R^2 - rho^2), the stock no higher, the design
//         no lower than q_z >= c_z - sqrt((R - delta)^2 - rho^2), and
//         sqrt(R^2 - rho^2) - sqrt((R - delta)^2 - rho^2) >= delta (q above c: more still);
//         so the vertical gouge is never smaller than the interference (larger on slopes and
//         at the surface's edges), up to the grid's sampling of it;
//         scallop = max(0, stock - design) |n_z| (n the surface's unit normal there: the
//         distance from the stock's point to the surface's tangent plane, the scallop height
//         along the normal as H is meant; exact on planes, within O(h^2 curvature) on
//         curved surfaces) (max, where, 99th percentile, mean, points and area above H:
//         "uncut"), counts of moves, rapids that cut (> gougeTolerance below
//         what was there) and the first such line. Deterministic.
// Reach:  a point q left more than H above the surface is "unreachable" when the ball
//         cannot come within H of it from above at all, as near as one can tell: the ball
//         touches q only from c = q + R n (n the upward unit normal; q's foot found by
//         gouge.hpp's closest point), and if the drop envelope over c (envelope.hpp's
//         DropCutter: the lowest centre on that vertical proven clear of the whole surface)
//         lies L above c, the ball there stays |c + L z - q| - R = sqrt(R^2 + 2 R L n_z +
//         L^2) - R from q. Where that exceeds H (a concave radius below R, a gap narrower than
//         the ball, a wall) the point is counted in `unreachable` (area, worst material left:
//         a smaller tool's work) and left out of the scallop figures, which are then the
//         plan's own doing. Not a proof that no other centre comes nearer (a centre beside c
//         may): a heuristic classification of what is left, in the report for what it is.
//         Only points above H are classified, on every core, within maxReachChecks, in
//         blocks of a fixed size each with its own drop cutter (whose heights depend on the
//         queries before: its Newton seed), so that the classes are the same for any number
//         of threads.
// Vertical walls: the vertical measure is ill-posed over a vertical wall lying along grid
//         points: the design there is the wall's top, while a ball running beside the wall,
//         tangent to it, lowers those points to its centre's height, a "gouge" of the wall's
//         height where nothing of the part was cut. So on a Surface, a point whose vertical
//         gouge exceeds the tolerance is checked against the ball that cut it lowest: the
//         line move that set its stock (sweepMoves' lowestMove), its centre c at the
//         minimiser (the same closed form), and the vertical segment from c up to above the
//         whole surface (envelope.hpp's ballTop): when SurfaceDistance::segmentClearance
//         proves it R - gougeTolerance clear, the ball at c is that far from every surface
//         point and joined to the air above the part (a ball inside the part, or under its
//         edge, meets the surface on the way up), so no material deeper than gougeTolerance was
//         cut by it, and no other move cut that point lower. Such a point is "cleared": out
//         of the gouge figures, counted apart (clearedGougePoints). The proof is made at c
//         itself, not by comparing c with a drop envelope: beside an edge the lowest clear
//         height of the envelope jumps (a centre R - 1e-5 beside a steep patch's edge is
//         clear at any height by R - 1e-4, while its exact contact stands 2e-3 above the
//         edge), so a drop envelope found from a nearby contact would refuse a ball the
//         direct proof clears.
//         Arcs, and points past maxClearanceChecks, are not cleared (they count as gouges).
//         On a Mesh the same proof runs against the mesh as the top of a solid (meshWithSkirt:
//         walls under its open edges, down to its lowest vertex, at the edges themselves), for
//         centres at or above that lowest z: such a ball reaches into a grid point's column
//         only across the walls (its widest slice, at its centre's height, meets them first)
//         or from above the top, both proven R - gougeTolerance away. (OCCT's shape.stl,
//         plan's defaults: 1.695 mm of such "gouges" beside its walls, 0.0024 mm once
//         cleared, against a tolerance of 0.0025 mm.) Designs from elsewhere (a part's exact
//         faces through a callback) are not checked.
// Meshes: a triangle mesh (mesh.hpp) may stand for the surface: the grid covers its
//         vertices' xy box; the design at a grid point is the highest of the triangles over
//         it, exactly (barycentric coordinates in the xy projection, each >= -1e-12 so that a
//         point on an edge belongs to both triangles and to the footprint despite rounding;
//         vertical triangles show only through their neighbours), |n_z| the winning
//         triangle's. Reach as above with n the winning triangle's upward unit normal and the
//         drop envelope mesh_drop.hpp's exact MeshDropCutter (at a concave crease between
//         facets a ball leaves material whatever its radius: such points above H count as
//         unreachable). The sweep and the comparison are the same.
// Cost:   O(P + sum over moves of the grid points within R of the move's box) time,
//         O(P) memory, P the grid points; the design O(P) Newton solves of a few steps.
// Errors: scallop::Error for invalid options (naming the option and value), non-finite
//         moves (naming the program's line), a grid over its budget (maxPoints), a sweep
//         over its budget (maxEvaluations, counted before sweeping).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "scallop/paths/envelope.hpp"
#include "scallop/paths/machine_program.hpp"
#include "scallop/paths/gouge.hpp"
#include "scallop/geometry/mesh.hpp"
#include "scallop/geometry/surface.hpp"
#include "scallop/paths/toolpath.hpp"
#include "scallop/geometry/vector.hpp"

namespace scallop {

/// A move of the ball's CENTRE (see toolpath.hpp for arcs: `center` shares the normal
/// coordinate of `start`; the end's may differ: a helix, linear in the angle).
struct SweptMove {
  MoveKind kind = MoveKind::line;
  Vec3 start;
  Vec3 end;
  Vec3 center;                    ///< arc
  ArcPlane plane = ArcPlane::xy;  ///< arc
  bool clockwise = true;          ///< arc: G2 as seen from the plane normal's positive end
  bool rapid = false;             ///< G0
  std::size_t line = 0;           ///< the program's line (0: from a ToolPath)
};

/// The moves of a program as ball centres (tip + R z). R must be positive and finite.
std::vector<SweptMove> sweptMoves(const GcodeProgram& program, double toolRadius);

/// The moves of a tool path: each pass from its start, and the straight feed link from the
/// previous pass's end when the pass has no retract. Retracts are not simulated: the path
/// leaves their height to the G-code writer (gcode.hpp), above everything.
std::vector<SweptMove> sweptMoves(const ToolPath& path);

/// G18/G19 helices' branch and bound: within kHelixTolerance (R + |centre| + r) above the
/// true lowest point (with at most kHelixMaxPieces pieces per grid point: a first-order
/// bound needs many pieces about a flat minimum, so the tolerance is not rounding's).
inline constexpr double kHelixTolerance = 1e-7;
inline constexpr int kHelixMaxPieces = 4000;

/// The lowest z of the ball of radius R swept along `move`, on the vertical line through
/// (x, y); +infinity when the ball never comes within R of it in xy. See the contract.
double sweptBallLowest(const SweptMove& move, double toolRadius, double x, double y);

/// A height per grid point: z[j * columns + i] at (x0 + i spacing, y0 + j spacing).
struct HeightGrid {
  double x0 = 0.0;
  double y0 = 0.0;
  double spacing = 0.0;
  std::size_t columns = 0;
  std::size_t rows = 0;
  std::vector<double> z;
  Vec2 point(std::size_t i, std::size_t j) const {
    return {x0 + static_cast<double>(i) * spacing, y0 + static_cast<double>(j) * spacing};
  }
};

struct SimulationOptions {
  double toolRadius = 0.0;  ///< R > 0, the surface's units
  /// H in (0, R): the scallop height aimed at; the default grid spacing and "uncut" follow.
  double scallopHeight = 0.0;
  /// d > 0, or 0: d = H (R - H) / (2 sqrt(2RH - H^2)) (see the contract).
  double resolution = 0.0;
  /// Grown around the surface's xy box, >= 0; NaN: two grid spacings.
  double margin = std::numeric_limits<double>::quiet_NaN();
  /// The stock's flat top before the cut; none: the control points' highest z (the top of
  /// the surface's bounding box).
  std::optional<double> stockTop;
  /// A finishing pass's stock: the design surface raised by this (>= 0) wherever there is
  /// surface (no material off the footprint), capped by the flat top; none: the flat block.
  /// It is what a plan's links assume roughing left (linking.hpp's clearance covers up to
  /// its margin): a rapid that cuts it would hit material on the machine.
  std::optional<double> stockAllowance;
  /// A gouge deeper than this counts (points, area, the CLI's --fail-on-gouge); >= 0.
  /// NaN: 1e-4 in or 0.0025 mm (ten quanta of the G-code's rounding, gcode.hpp).
  double gougeTolerance = std::numeric_limits<double>::quiet_NaN();
  /// Tell the points left above H that the ball cannot reach from above from those it
  /// could (see the contract's Reach); false: every point counts in the scallop figures.
  bool classifyReach = true;
  /// Budget: reach checks (one closest point and one drop-cutter height each); past it the
  /// remaining points count as reachable (in the scallop figures), and the report says so.
  std::size_t maxReachChecks = 400'000;
  /// Clear vertical gouges on a Surface or a Mesh by a proof at the centre that cut them
  /// lowest (see the contract's Vertical walls); false: every one counts.
  bool clearVerticalGouges = true;
  /// Budget of those checks (one segment-clearance proof each); past it the rest count as gouges.
  std::size_t maxClearanceChecks = 200'000;
  std::size_t maxPoints = 4'000'000;  ///< grid budget (three doubles per point: 96 MB)
  /// Sweep budget: the (move, grid point) pairs in the moves' boxes grown by R, summed
  /// before the sweep (about a minute of work at the measured 50-60 million per second).
  double maxEvaluations = 4e9;
};

struct SimulationReport {
  Units units = Units::inch;
  double toolRadius = 0.0;
  double scallopHeight = 0.0;
  double gougeTolerance = 0.0;
  double stockTop = 0.0;
  double heightErrorBound = 0.0;  ///< s d / 2: how much a scallop ridge can hide between points
  HeightGrid stock;               ///< the z-map after the cut
  HeightGrid design;              ///< the visible surface; -infinity = no surface
  std::vector<double> designNormalZ;  ///< |n_z| of its unit normal per grid point (0: none)
  std::size_t moves = 0, rapids = 0, arcs = 0;
  std::size_t rapidsCutting = 0;       ///< rapids that removed more than gougeTolerance
  std::size_t firstRapidCutLine = 0;   ///< the program line of the first one (0: none)
  std::size_t surfacePoints = 0;
  double maxGouge = 0.0;               ///< max(0, design - stock)
  std::optional<Vec3> maxGougeAt;      ///< (x, y, design z) when maxGouge > 0
  std::size_t gougePoints = 0;         ///< design - stock > gougeTolerance, not cleared
  /// Points whose vertical gouge exceeds the tolerance while the ball that cut them lowest
  /// is proven clear (see the contract's Vertical walls): out of maxGouge and gougePoints.
  std::size_t clearedGougePoints = 0;
  double maxClearedGouge = 0.0;        ///< their largest vertical measure
  std::size_t clearanceChecks = 0;     ///< points checked
  bool clearanceBudgetExhausted = false;  ///< some points beyond the tolerance were not checked
  /// Per grid point: 1 where a vertical gouge was cleared.
  std::vector<unsigned char> clearedGouge;
  double gougeArea = 0.0;              ///< gougePoints d^2
  double maxScallop = 0.0;
  std::optional<Vec3> maxScallopAt;    ///< (x, y, design z)
  double scallopP99 = 0.0;             ///< 99th percentile of the scallop over surface points
  double meanScallop = 0.0;
  std::size_t uncutPoints = 0;         ///< scallop > H, reachable
  double uncutArea = 0.0;              ///< uncutPoints d^2
  /// Per grid point: 1 where the scallop exceeds H and the ball cannot reach (see Reach).
  std::vector<unsigned char> unreachable;
  std::size_t unreachablePoints = 0;   ///< out of the scallop figures above
  double unreachableArea = 0.0;        ///< unreachablePoints d^2: left for a smaller tool
  double maxUnreachableScallop = 0.0;  ///< the material left there, at most
  std::optional<Vec3> maxUnreachableAt;
  std::size_t reachChecks = 0;         ///< points classified
  bool reachBudgetExhausted = false;   ///< some points above H were not classified
  double reachSeconds = 0.0;
  std::size_t sweptPointVisits = 0;    ///< (move, grid point) pairs evaluated
  double designSeconds = 0.0;
  double sweepSeconds = 0.0;
  double seconds = 0.0;
};

/// The grid of the contract for `surface` and `options` (validated), heights all
/// -infinity. Throws scallop::Error past the budget.
HeightGrid simulationGrid(const Surface& surface, const SimulationOptions& options);

/// The same over a mesh's vertices.
HeightGrid simulationGrid(const Mesh& mesh, const SimulationOptions& options);

/// The same over the xy box [low, high] (a part known by its bounding box: a CAD part's).
HeightGrid simulationGrid(Vec2 low, Vec2 high, const SimulationOptions& options);

/// Design heights from elsewhere (a STEP or IGES part's exact faces, cad_tessellation.hpp):
/// fills grid.z (-infinity off the part) and normalZ (|n_z| of the unit normal per point,
/// sized as grid.z; 0 where there is no surface).
using DesignHeightsFunction = std::function<void(HeightGrid& grid, std::vector<double>& normalZ)>;

/// The highest triangle of `mesh` over every point of `grid` (see the contract's Meshes);
/// `normalZ`, if given, receives |n_z| of its unit normal (0 where there is none).
void designHeights(const Mesh& mesh, HeightGrid& grid, std::vector<double>* normalZ = nullptr);

/// Per point of `grid`, the triangle of `mesh` that designHeights takes there (the highest
/// over it), or kNoDesignTriangle: rest finishing's normals on a mesh.
inline constexpr std::uint32_t kNoDesignTriangle = 0xffffffffu;
std::vector<std::uint32_t> designTriangles(const Mesh& mesh, const HeightGrid& grid);

/// The visible height of `surface` at every point of `grid` (see the contract); `normalZ`,
/// if given, receives |n_z| of the unit normal there (0 off the surface). A trimmed patch
/// (surface.hpp's trims) counts only inside its face: its cells outside the face are skipped
/// (face_trim.hpp's classifyCell) and a hit in a cell on a trimming curve is kept only where
/// keepsPoint holds.
void designHeights(const Surface& surface, HeightGrid& grid, std::vector<double>* normalZ = nullptr);

/// The (move, grid point) pairs in the moves' boxes grown by R: what the sweep may evaluate.
double sweepEvaluations(const std::vector<SweptMove>& moves, double toolRadius, const HeightGrid& stock);

/// Lowers `stock` by every move (the z-map sweep); returns (move, point) pairs evaluated.
/// `lowered`, if given, receives per move the largest amount it lowered the stock by.
std::size_t sweepMoves(const std::vector<SweptMove>& moves, double toolRadius, HeightGrid& stock,
                       std::vector<double>* lowered = nullptr);

/// No move lowered the stock there (sweepMoves' lowestMove).
inline constexpr std::uint32_t kNoMove = 0xffffffffu;

/// The same; `lowestMove`, if given, receives per grid point the first move that cut it
/// lowest (kNoMove where none lowered it).
std::size_t sweepMoves(const std::vector<SweptMove>& moves, double toolRadius, HeightGrid& stock,
                       std::vector<double>* lowered, std::vector<std::uint32_t>* lowestMove);

/// The ball that touches a surface point q from above, as the contract's Reach defines it:
/// the centre c = q + R n (n the upward unit normal at q's foot point) raised onto the drop
/// envelope over c (`cutter`, whose radius is R), and how far that ball stays from q,
/// gap = |centre - q| - R = sqrt(R^2 + 2 R L n_z + L^2) - R for a lift L >= 0. No centre
/// where nothing of the surface lies within R of that vertical.
struct ReachWitness {
  std::optional<Vec3> centre;
  double gap = std::numeric_limits<double>::infinity();
};
ReachWitness reachWitness(const SurfaceDistance& distance, DropCutter& cutter, Vec3 q, double radius);

/// The gap above: how far a ball of radius R lifted by L >= 0 from q + R n stays from q,
/// sqrt(R^2 + 2 R L n_z + L^2) - R.
double reachGap(double radius, double lift, double normalZ);

/// The whole simulation: grid, design, sweep, comparison.
SimulationReport simulateCut(const Surface& surface, const std::vector<SweptMove>& moves,
                             const SimulationOptions& options);

/// The whole simulation on a mesh (see the contract's Meshes).
SimulationReport simulateCut(const Mesh& mesh, const std::vector<SweptMove>& moves,
                             const SimulationOptions& options);

/// The whole simulation on `grid` (from simulationGrid, heights -infinity) with the design
/// from `design`; `highest` is the part's highest point (the default stock top). Points left
/// above H are classified by reach on `reachMesh` (the part's tessellation: the normal and the
/// drop envelope from the mesh, as the contract's Meshes), or not at all without one.
SimulationReport simulateCut(Units units, HeightGrid grid, double highest, const DesignHeightsFunction& design,
                             const std::vector<SweptMove>& moves, const SimulationOptions& options,
                             const Mesh* reachMesh = nullptr);

/// simulateCut on a program (its units must be the surface's).
SimulationReport verifyProgram(const Surface& surface, const GcodeProgram& program,
                               const SimulationOptions& options);

/// simulateCut on a program over a mesh (its units must be the mesh's).
SimulationReport verifyProgram(const Mesh& mesh, const GcodeProgram& program, const SimulationOptions& options);

/// simulateCut on a program with the design from `design` (the program's units must be `units`).
SimulationReport verifyProgram(Units units, HeightGrid grid, double highest, const DesignHeightsFunction& design,
                               const GcodeProgram& program, const SimulationOptions& options,
                               const Mesh* reachMesh = nullptr);

/// simulateCut on a tool path (options.toolRadius 0 takes path.toolRadius).
SimulationReport verifyToolPath(const Surface& surface, const ToolPath& path, SimulationOptions options);

}  // namespace scallop
